#include "oscar/registry/clock_estimator.hpp"

#include <algorithm>

namespace oscar {

std::optional<ClockSample> ClockEstimator::add(const ClockProbeStamps& s) {
  const ClockSample sample{.offset = ((s.t1 - s.t2) + (s.t4 - s.t3)) / 2,
                           .round_trip = (s.t4 - s.t1) - (s.t3 - s.t2)};
  if (sample.round_trip < std::chrono::nanoseconds::zero()) return std::nullopt;
  window_.push_back(sample);
  if (window_.size() > kWindow) window_.pop_front();
  return sample;
}

std::optional<ClockEstimate> ClockEstimator::estimate() const {
  if (window_.empty()) return std::nullopt;
  const auto best = std::min_element(
      window_.begin(), window_.end(),
      [](const ClockSample& a, const ClockSample& b) { return a.round_trip < b.round_trip; });
  return ClockEstimate{
      .offset = best->offset, .uncertainty = best->round_trip / 2, .samples = window_.size()};
}

}  // namespace oscar
