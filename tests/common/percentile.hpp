#pragma once
// The benchmarks' percentile: the value at rank q * n of the sorted samples (q in 0..1; q = 1 is
// the largest), 0 for no samples.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace oscar::test {

inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

}  // namespace oscar::test
