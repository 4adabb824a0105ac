#pragma once
/// @file ClockEstimator: how far a host's wall clock is from the registry's, from NTP-style
/// probes (docs/boot.md, "Clocks"). No DDS: the monitor feeds it the four stamps of each probe.

#include <chrono>
#include <cstddef>
#include <deque>
#include <optional>

namespace oscar {

/// One probe's four wall-clock stamps: t1 probe sent and t4 echo received on the host's clock,
/// t2 probe received and t3 echo sent on the registry's clock (nanoseconds since the epoch).
struct ClockProbeStamps {
  std::chrono::nanoseconds t1{};
  std::chrono::nanoseconds t2{};
  std::chrono::nanoseconds t3{};
  std::chrono::nanoseconds t4{};
};

/// What one probe says: the host's clock minus the registry's, and the time the probe spent on
/// the network (its round trip without the registry's time between t2 and t3).
struct ClockSample {
  std::chrono::nanoseconds offset{};
  std::chrono::nanoseconds round_trip{};
};

/// The estimate: the offset of the sample with the smallest round trip among the last ones; the
/// true offset lies within ± uncertainty of it (half that round trip), whatever the split of the
/// delay between the two directions.
struct ClockEstimate {
  std::chrono::nanoseconds offset{};
  std::chrono::nanoseconds uncertainty{};
  std::size_t samples{};
};

/// Keeps the last kWindow samples of one host and picks the one least disturbed by queueing.
class ClockEstimator {
 public:
  static constexpr std::size_t kWindow = 16;

  /// The sample of one probe: offset = ((t1 - t2) + (t4 - t3)) / 2,
  /// round trip = (t4 - t1) - (t3 - t2). Kept unless its round trip is negative (a clock was
  /// stepped while the probe was out), which gives std::nullopt.
  std::optional<ClockSample> add(const ClockProbeStamps& stamps);
  /// The estimate from the samples kept; std::nullopt before the first.
  std::optional<ClockEstimate> estimate() const;

 private:
  std::deque<ClockSample> window_;
};

}  // namespace oscar
