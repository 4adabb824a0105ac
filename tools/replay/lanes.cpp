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

double Lanes::lateness_us(double quantile) const {
  std::uint64_t total = 0;
  for (const auto& n : lateness_) total += n;
  if (total == 0) return 0;
  const auto rank = static_cast<std::uint64_t>(quantile * static_cast<double>(total - 1));
  std::uint64_t seen = 0;
  for (std::size_t bin = 0; bin < kLatenessBins; ++bin) {
    seen += lateness_[bin];
    if (seen > rank) return static_cast<double>(bin) * 10.0;
  }
  return static_cast<double>(kLatenessBins - 1) * 10.0;
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
      if (!wait_) {
        const auto late =
            std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - (start_ + p.due));
        const auto bin = static_cast<std::size_t>(std::max<std::int64_t>(late.count(), 0) / 10);
        ++lateness_[std::min(bin, kLatenessBins - 1)];
      }
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
