#include "held_pulls.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "oscar/input.hpp"

namespace oscar::internal {

std::optional<RingEntry> first_at_or_after(const RingBuffer& ring, Stamp t) {
  auto entries = ring.range(t, std::numeric_limits<Stamp>::max());  // ascending t
  if (entries.empty()) return std::nullopt;
  return std::move(entries.front());
}

HeldPulls::HeldPulls(const RingBuffer& ring) : ring_(ring) {}

HeldPulls::~HeldPulls() {
  std::list<Held> left;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    left.swap(held_);
  }
  changed_.notify_all();
  if (timer_.joinable()) timer_.join();
  for (auto& h : left) h.answer(std::nullopt);
}

void HeldPulls::ask(const std::string& requester, Stamp t, std::chrono::nanoseconds wait,
                    Answer answer) {
  std::unique_lock lock(mutex_);
  // Looked up under the lock that arrived() takes: a cue pushed before this look-up is found
  // here, one pushed after it is offered to arrived(), which then sees this pull held.
  auto found = first_at_or_after(ring_, t);
  if (found || wait <= std::chrono::nanoseconds::zero() || stopping_) {
    lock.unlock();
    answer(std::move(found));
    return;
  }
  const auto mine = std::count_if(held_.begin(), held_.end(),
                                  [&](const Held& h) { return h.requester == requester; });
  if (static_cast<std::size_t>(mine) >= kMaxHeldPulls) {
    throw std::length_error(
        fmt::format("pull of {} refused: {} of its pulls wait for a cue already, and a producer "
                    "holds at most {} per input",
                    requester, mine, kMaxHeldPulls));
  }
  held_.push_back({requester, t, std::chrono::steady_clock::now() + wait, std::move(answer)});
  if (!timer_.joinable()) timer_ = std::thread([this] { expire_until_stopped(); });
  changed_.notify_all();
}

void HeldPulls::arrived(const RingEntry& entry) {
  std::list<Held> due;
  {
    std::lock_guard lock(mutex_);
    for (auto it = held_.begin(); it != held_.end();) {
      const auto next = std::next(it);
      if (entry.t >= it->t) due.splice(due.end(), held_, it);
      it = next;
    }
  }
  if (!due.empty()) changed_.notify_all();
  for (auto& h : due) h.answer(entry);
}

std::size_t HeldPulls::held() const {
  std::lock_guard lock(mutex_);
  return held_.size();
}

void HeldPulls::expire_until_stopped() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (held_.empty()) {
      changed_.wait(lock);
      continue;
    }
    // A copy: wait_until() reads its deadline again after waking, and while it waits (unlocked)
    // arrived() may answer and free the pull it came from.
    const auto until =
        std::min_element(held_.begin(), held_.end(), [](const Held& a, const Held& b) {
          return a.until < b.until;
        })->until;
    if (changed_.wait_until(lock, until) == std::cv_status::no_timeout) continue;
    std::list<Held> ended;
    const auto now = std::chrono::steady_clock::now();
    for (auto it = held_.begin(); it != held_.end();) {
      const auto next = std::next(it);
      if (it->until <= now) ended.splice(ended.end(), held_, it);
      it = next;
    }
    lock.unlock();
    // A last look: a ring nobody watches (a harness's) may hold the cue by now.
    for (auto& h : ended) h.answer(first_at_or_after(ring_, h.t));
    lock.lock();
  }
}

}  // namespace oscar::internal
