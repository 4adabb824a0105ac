#pragma once
// Internal: the restarts after failures a module may still have (restart policy `max` within
// `window`, docs/boot.md). Only restarts within the last `window` count, so a module that fails
// now and then over a long run is restarted each time, while one that fails over and over is
// given up.

#include <chrono>
#include <deque>

namespace oscar::internal {

class RestartBudget {
 public:
  using Clock = std::chrono::steady_clock;

  /// True if a restart at `now` keeps to at most `max` restarts within `window`.
  bool allows(Clock::time_point now, int max, Clock::duration window);
  /// A restart after a failure happened at `now`.
  void record(Clock::time_point now) { restarts_.push_back(now); }
  /// Restarts within the `window` before `now` (what `allows` compares with `max`).
  int within(Clock::time_point now, Clock::duration window);
  /// The restarts recorded (oldest first); older ones may be forgotten once out of the window.
  const std::deque<Clock::time_point>& restarts() const { return restarts_; }

 private:
  std::deque<Clock::time_point> restarts_;  // oldest first, none older than the last window
};

}  // namespace oscar::internal
