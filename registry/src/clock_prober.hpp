#pragma once
// The monitor's side of the host clock measurement (docs/boot.md, "Clocks"): probes the
// registry's clock NTP-style and publishes this host's estimate on oscar/registry/clocks.

#include <chrono>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "oscar/registry/clock_estimator.hpp"
#include "oscar/registry/clock_topics.hpp"
#include "oscar/topic_io.hpp"

namespace oscar {

/// The test hook OSCAR_CLOCK_OFFSET_MS, for tests only: milliseconds added to the wall clock the
/// monitor stamps its probes with, so that a test can fake a host whose clock is off. Zero when
/// the variable is not set.
/// @throws std::invalid_argument when it is set to anything but a whole number of milliseconds.
std::chrono::nanoseconds test_clock_offset_from_environment();

class ClockProber {
 public:
  /// Starts probing at once: every 200 ms for the first 3 s, then every second.
  ClockProber(DdsParticipant& participant, std::string host, long monitor_pid,
              std::chrono::nanoseconds test_offset);
  ~ClockProber();
  ClockProber(const ClockProber&) = delete;
  ClockProber& operator=(const ClockProber&) = delete;

 private:
  std::chrono::nanoseconds now() const;
  void on_echo(const ClockEcho& echo);

  std::string host_;
  long monitor_pid_;
  std::chrono::nanoseconds test_offset_;
  std::mutex mutex_;
  ClockEstimator estimator_;
  std::set<unsigned long long> in_flight_;  // probes sent and not yet answered
  TopicWriter<ClockProbe, ClockProbePubSubType> probes_;
  TopicWriter<HostClock, HostClockPubSubType> estimates_;
  TopicReader<ClockEcho, ClockEchoPubSubType> echoes_;
  std::jthread prober_;
};

}  // namespace oscar
