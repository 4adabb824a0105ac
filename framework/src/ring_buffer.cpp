#include "oscar/ring_buffer.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar {

void check_time_range(Stamp t0, Stamp t1) {
  if (t0 > t1) {
    throw std::invalid_argument(
        fmt::format("inverted time range [{}, {}]: the start must not be after the end", t0, t1));
  }
}

RingBuffer::RingBuffer(std::size_t depth) : slots_(depth) {
  if (depth == 0) throw std::invalid_argument("ring buffer depth must be at least 1, got 0");
}

std::shared_ptr<const void> RingBuffer::push(std::shared_ptr<const void> cue, Stamp t,
                                             Stamp received) {
  std::shared_ptr<const void> evicted;
  bool waited_for = false;
  {
    std::lock_guard lock(mutex_);
    evicted = std::move(slots_[next_].cue);
    slots_[next_] = RingEntry{std::move(cue), t, received, ++pushed_};
    next_ = (next_ + 1) % slots_.size();
    count_ = std::min(count_ + 1, slots_.size());
    waited_for = waiting_ > 0;
  }
  // Skipped without waiters: every push of a publisher runs here between a cue's stamp and its
  // delivery, and even an empty notify_all() is a call into code the cue's payload has pushed
  // out of the cache.
  if (waited_for) arrived_.notify_all();
  return evicted;
}

std::shared_ptr<const void> RingBuffer::drop_oldest_if_full() {
  std::lock_guard lock(mutex_);
  if (count_ < slots_.size()) return nullptr;
  --count_;  // the oldest is the slot the next push writes
  return std::move(slots_[next_].cue);
}

std::size_t RingBuffer::size() const {
  std::lock_guard lock(mutex_);
  return count_;
}

std::uint64_t RingBuffer::pushed() const {
  std::lock_guard lock(mutex_);
  return pushed_;
}

std::vector<RingEntry> RingBuffer::held_locked() const {
  std::vector<RingEntry> out;
  out.reserve(count_);
  const std::size_t first = (next_ + slots_.size() - count_) % slots_.size();
  for (std::size_t i = 0; i < count_; ++i) out.push_back(slots_[(first + i) % slots_.size()]);
  return out;
}

std::optional<RingEntry> RingBuffer::latest() const {
  std::lock_guard lock(mutex_);
  if (count_ == 0) return std::nullopt;
  return slots_[(next_ + slots_.size() - 1) % slots_.size()];
}

std::vector<RingEntry> RingBuffer::latest(std::size_t n) const {
  std::lock_guard lock(mutex_);
  auto held = held_locked();
  if (held.size() > n) held.erase(held.begin(), held.end() - static_cast<std::ptrdiff_t>(n));
  return held;
}

std::optional<RingEntry> RingBuffer::at_or_before(Stamp t) const {
  std::lock_guard lock(mutex_);
  std::optional<RingEntry> best;
  for (const auto& e : held_locked()) {
    if (e.t <= t && (!best || e.t >= best->t)) best = e;
  }
  return best;
}

std::optional<RingEntry> RingBuffer::nearest(Stamp t) const {
  std::lock_guard lock(mutex_);
  std::optional<RingEntry> best;
  const auto distance = [t](Stamp s) { return s > t ? s - t : t - s; };
  for (const auto& e : held_locked()) {
    if (!best || distance(e.t) < distance(best->t) ||
        (distance(e.t) == distance(best->t) && e.t < best->t)) {
      best = e;
    }
  }
  return best;
}

std::vector<RingEntry> RingBuffer::range(Stamp t0, Stamp t1) const {
  check_time_range(t0, t1);
  std::lock_guard lock(mutex_);
  std::vector<RingEntry> out;
  for (auto& e : held_locked()) {
    if (e.t >= t0 && e.t <= t1) out.push_back(std::move(e));
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const RingEntry& a, const RingEntry& b) { return a.t < b.t; });
  return out;
}

std::optional<RingEntry> RingBuffer::wait_next(std::uint64_t after_index,
                                               std::chrono::nanoseconds timeout) const {
  std::unique_lock lock(mutex_);
  ++waiting_;  // under the lock until wait_for() releases it: no push can slip in unnoticed
  const bool arrived = arrived_.wait_for(lock, timeout, [&] { return pushed_ > after_index; });
  --waiting_;
  if (!arrived) return std::nullopt;
  for (const auto& e : held_locked()) {
    if (e.index > after_index) return e;
  }
  return std::nullopt;  // cleared in between
}

void RingBuffer::clear() {
  std::lock_guard lock(mutex_);
  count_ = 0;
}

}  // namespace oscar
