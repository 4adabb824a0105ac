#include "lanes.hpp"

#include <algorithm>

namespace oscar::replay {

struct Lanes::Lane {
  std::deque<Pending> queue;
  std::condition_variable ready;
  std::thread thread;
};

Lanes::Lanes(Clock::time_point start, std::size_t ahead_bytes, const std::atomic<bool>& stop,
             std::function<bool(const Pending&)> wait)
    : start_(start), ahead_bytes_(ahead_bytes), stop_(stop), wait_(std::move(wait)) {}

Lanes::~Lanes() {
  {
    std::lock_guard lock(mutex_);
    cancelled_ = true;
    closing_ = true;
    for (auto& [key, lane] : lanes_) lane->ready.notify_all();
  }
  space_.notify_all();
  for (auto& [key, lane] : lanes_) lane->thread.join();
}

bool Lanes::add(Pending p) {
  std::unique_lock lock(mutex_);
  // Room is checked in slices: `stop` is set by a signal handler, which cannot notify.
  while (queued_bytes_ >= ahead_bytes_ && !stopping()) {
    space_.wait_for(lock, std::chrono::milliseconds(100));
  }
  if (stopping()) return false;
  auto& lane = lanes_[p.lane];
  if (!lane) {
    lane = std::make_unique<Lane>();
    lane->thread = std::thread([this, l = lane.get()] { run(*l); });
  }
  queued_bytes_ += p.bytes.size();
  lane->queue.push_back(std::move(p));
  lane->ready.notify_one();
  return true;
}

void Lanes::drain() {
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
    for (auto& [key, lane] : lanes_) lane->ready.notify_all();
  }
  for (auto& [key, lane] : lanes_) lane->thread.join();
  lanes_.clear();
}

void Lanes::run(Lane& lane) {
  for (;;) {
    Pending p;
    {
      std::unique_lock lock(mutex_);
      lane.ready.wait(lock, [&] { return cancelled_ || !lane.queue.empty() || closing_; });
      if (cancelled_ || lane.queue.empty()) return;
      p = std::move(lane.queue.front());
      lane.queue.pop_front();
    }
    if (wait_) {
      if (!wait_(p)) cancelled_ = true;
    } else {
      // In slices, so that a stop ends a long gap in the recording.
      const auto due = start_ + p.due;
      while (!stopping() && Clock::now() < due) {
        std::this_thread::sleep_until(std::min(due, Clock::now() + std::chrono::milliseconds(100)));
      }
    }
    const auto size = p.bytes.size();
    if (!stopping()) {
      p.publish(p.bytes);
      ++published_;
    }
    {
      std::lock_guard lock(mutex_);
      queued_bytes_ -= size;
    }
    space_.notify_one();
    if (stopping()) space_.notify_all();
  }
}

}  // namespace oscar::replay
