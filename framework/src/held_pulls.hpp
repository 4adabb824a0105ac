#pragma once
// Pulls a producer holds until they can be answered right (PullQuery::kAtOrAfter, docs/kernels.md
// "Pull and prefetch"): "the first cue generated at or after t", held until such a cue is in the
// producer's output ring, up to the wait the consumer gave, then answered with nothing. A pull
// source in this process and the pull server of a frame each keep one. Requests are answered
// where the output takes a new cue (arrived(), on the publishing thread) or, at the end of
// their wait, on this object's own timer thread; never on the kernel thread that asked.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <list>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "oscar/ring_buffer.hpp"

namespace oscar::internal {

/// The first entry of `ring` generated at or after `t`, if it holds one.
std::optional<RingEntry> first_at_or_after(const RingBuffer& ring, Stamp t);

class HeldPulls {
 public:
  /// Gets the answer: the matching entry, or nothing (the wait ended without one, or the holder
  /// stops).
  using Answer = std::function<void(std::optional<RingEntry>)>;

  /// Holds pulls for cues of `ring`.
  explicit HeldPulls(const RingBuffer& ring);
  /// Answers every held pull with nothing.
  ~HeldPulls();
  HeldPulls(const HeldPulls&) = delete;
  HeldPulls& operator=(const HeldPulls&) = delete;

  /// Answers at once if the ring holds a cue generated at or after t (or `wait` is zero), else
  /// holds the pull up to `wait`.
  /// @throws std::length_error if `requester` has kMaxHeldPulls pulls held already (naming it).
  void ask(const std::string& requester, Stamp t, std::chrono::nanoseconds wait, Answer answer);
  /// A new cue is in the ring: answers the pulls it matches.
  void arrived(const RingEntry& entry);
  /// Pulls held now.
  std::size_t held() const;

 private:
  struct Held {
    std::string requester;
    Stamp t = 0;
    std::chrono::steady_clock::time_point until{};
    Answer answer;
  };
  void expire_until_stopped();  // the timer thread

  const RingBuffer& ring_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::list<Held> held_;
  bool stopping_ = false;
  std::thread timer_;  // started with the first held pull
};

}  // namespace oscar::internal
