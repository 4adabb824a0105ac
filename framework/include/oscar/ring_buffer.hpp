#pragma once
/// @file The ring buffer behind every channel end (docs/kernels.md, seed 004 §2.2).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "oscar/time.hpp"

namespace oscar {

/// One cue as a ring buffer holds it: the shared immutable payload and its stamps.
struct RingEntry {
  std::shared_ptr<const void> cue;  ///< the payload; never copied by the buffer
  Stamp t = 0;                      ///< the cue's generation stamp (its header's first stamp)
  Stamp received = 0;               ///< when this buffer got it
  std::uint64_t index = 0;          ///< 1, 2, 3, ... in arrival order at this buffer
};

/// A fixed-depth buffer of the newest cues of one channel end, with access by time.
/// Checks a time range [t0, t1] as every query by range does.
/// @throws std::invalid_argument if t0 > t1 (an inverted time range), naming both.
void check_time_range(Stamp t0, Stamp t1);

/// Thread-safe: one or more producers, any number of readers. Queries by time assume nothing
/// about order (a rewired input may receive older stamps), so they scan at most `depth` entries.
class RingBuffer {
 public:
  /// @throws std::invalid_argument if depth is 0.
  explicit RingBuffer(std::size_t depth);

  /// Stores a cue, evicting the oldest when full; wakes waiters (if any). Returns the evicted cue
  /// (nullptr if none). A publisher calls drop_oldest_if_full() before it stamps the cue instead,
  /// so that nothing is freed between the stamp and the cue's delivery.
  std::shared_ptr<const void> push(std::shared_ptr<const void> cue, Stamp t, Stamp received);
  /// Makes room for the next push: if the ring is full, drops its oldest entry and returns that
  /// cue (else nullptr), so that a publisher frees it before it stamps the next cue.
  std::shared_ptr<const void> drop_oldest_if_full();

  std::size_t depth() const { return slots_.size(); }
  std::size_t size() const;
  /// Cues pushed since construction (including evicted ones).
  std::uint64_t pushed() const;

  std::optional<RingEntry> latest() const;
  /// The n newest entries, oldest first (fewer if fewer are held).
  std::vector<RingEntry> latest(std::size_t n) const;
  /// The newest entry with t <= `t`.
  std::optional<RingEntry> at_or_before(Stamp t) const;
  /// The entry whose t is closest to `t` (the older one on a tie).
  std::optional<RingEntry> nearest(Stamp t) const;
  /// Entries with t0 <= t <= t1, in ascending t.
  /// @throws std::invalid_argument if t0 > t1 (an inverted time range).
  std::vector<RingEntry> range(Stamp t0, Stamp t1) const;
  /// The first entry with an index greater than `after_index`, waiting up to `timeout` for it.
  /// If it was already evicted, the oldest held entry newer than `after_index` is returned.
  std::optional<RingEntry> wait_next(std::uint64_t after_index,
                                     std::chrono::nanoseconds timeout) const;
  /// Drops every entry (indices keep counting).
  void clear();

 private:
  std::vector<RingEntry> held_locked() const;  // oldest first

  mutable std::mutex mutex_;
  mutable std::condition_variable arrived_;
  std::vector<RingEntry> slots_;
  std::size_t next_ = 0;   // slot the next push writes
  std::size_t count_ = 0;  // entries held
  std::uint64_t pushed_ = 0;
  mutable std::size_t waiting_ = 0;  // threads in wait_next(): a push wakes only if there are any
};

}  // namespace oscar
