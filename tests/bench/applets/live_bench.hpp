#pragma once
// oscar-bench-applets --live (docs/benchmarks-applets.md): grants and preemptions across
// processes on a booted system.

#include <vector>

namespace oscar::bench {

struct LiveBenchOptions {
  int grants = 1000;  ///< measured grants (and as many preemptions) per run
  std::vector<int> applets{10, 100,
                           1000};  ///< one run per entry: applets in the coordinator's plan
  bool json = false;
};

/// Boots one system per entry of `applets`, measures, prints; returns the exit code.
int run_live_bench(const LiveBenchOptions& options);

}  // namespace oscar::bench
