#pragma once
// Lanes: publish replayed messages at their times, one thread per lane (a lane per topic), so
// that a large image being written never holds back a small cue due meanwhile. The reading
// thread queues messages up to a byte limit ahead of their publishing.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace oscar::replay {

/// A message read from the file, due `due` after the replay's start.
struct Pending {
  const void* lane = nullptr;  ///< messages with the same lane are published in order
  std::chrono::nanoseconds due{0};
  std::vector<std::uint8_t> bytes;
  std::function<void(std::vector<std::uint8_t>&)> publish;  ///< called at the due time
  std::string label;                                        ///< what step mode shows before it
};

/// What the lanes tell the reading thread about its pace (both optional).
struct ReadingPace {
  std::function<void()> ahead;   ///< in the reader, before it waits for room: it is far ahead
  std::function<void()> behind;  ///< in a lane: less than a quarter is queued, reading goes on
};

class Lanes {
 public:
  using Clock = std::chrono::steady_clock;
  /// Starts a thread per lane in `keys` (the `Pending::lane` values it will be given). `wait`
  /// replaces the wait for the due time (e.g. for Enter in step mode); it returns false to stop
  /// the replay.
  Lanes(const std::vector<const void*>& keys, Clock::time_point start, std::size_t ahead_bytes,
        const std::atomic<bool>& stop, std::function<bool(const Pending&)> wait = {},
        ReadingPace pace = {});
  ~Lanes();  ///< stops every lane, published or not
  Lanes(const Lanes&) = delete;
  Lanes& operator=(const Lanes&) = delete;

  /// Queues `p` on its lane. Once `ahead_bytes` are queued it blocks until the lanes have
  /// published half of them. False once the replay stops.
  /// @throws std::invalid_argument for a lane not given at construction.
  bool add(Pending p);
  /// Waits until every lane has published what it was given (or the replay stopped).
  void drain();
  std::uint64_t published() const { return published_; }
  /// How late publishing began against the due times, over every message published so far: the
  /// `quantile` (0..1) in microseconds, to 10 us (100 ms stands for anything later). 0 when
  /// stepping.
  double lateness_us(double quantile) const;

 private:
  struct Lane;
  void run(Lane& lane);
  void close_lanes();
  bool stopping() const { return stop_ || cancelled_; }

  const Clock::time_point start_;
  const std::size_t ahead_bytes_;
  const std::atomic<bool>& stop_;
  std::function<bool(const Pending&)> wait_;
  ReadingPace pace_;
  std::map<const void*, std::unique_ptr<Lane>> lanes_;  ///< fixed at construction
  std::mutex mutex_;                                    ///< the reader waits for room under it
  std::condition_variable space_;
  std::atomic<std::size_t> queued_bytes_{0};
  std::atomic<bool> reading_{true};  ///< until drain(): more messages may come
  std::atomic<bool> cancelled_{false};
  std::atomic<std::uint64_t> published_{0};
  static constexpr std::size_t kLatenessBins = 10001;  ///< 10 us each; the last: 100 ms or more
  std::vector<std::atomic<std::uint64_t>> lateness_ =
      std::vector<std::atomic<std::uint64_t>>(kLatenessBins);
};

}  // namespace oscar::replay
