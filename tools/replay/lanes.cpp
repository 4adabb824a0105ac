#include "lanes.hpp"

#include <algorithm>
#include <stdexcept>

#include "oscar/process_util.hpp"

namespace oscar::replay {

// Each lane has a lock of its own: the reading thread and the other lanes never hold up a lane
// that is about to publish.
struct Lanes::Lane {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<Pending> queue;
  bool closing = false;  ///< no more messages come: publish the queue, then end
  std::thread thread;
};

Lanes::Lanes(const std::vector<const void*>& keys, Clock::time_point start, std::size_t ahead_bytes,
             const std::atomic<bool>& stop, std::function<bool(const Pending&)> wait,
             ReadingPace pace)
    : start_(start),
      ahead_bytes_(ahead_bytes),
      stop_(stop),
      wait_(std::move(wait)),
      pace_(std::move(pace)) {
  // Started here, by the caller: the reading thread may lower its priority later, and threads
  // it started would inherit that.
  for (const auto* key : keys) {
    auto& lane = lanes_[key];
    if (lane) continue;
    lane = std::make_unique<Lane>();
    lane->thread = std::thread([this, l = lane.get()] { run(*l); });
  }
}

Lanes::~Lanes() {
  cancelled_ = true;
  space_.notify_all();
  close_lanes();
}

void Lanes::close_lanes() {
  reading_ = false;
  for (auto& [key, lane] : lanes_) {
    {
      std::lock_guard lock(lane->mutex);
      lane->closing = true;
    }
    lane->ready.notify_all();
  }
  for (auto& [key, lane] : lanes_) {
    if (lane->thread.joinable()) lane->thread.join();
  }
}

bool Lanes::add(Pending p) {
  const auto it = lanes_.find(p.lane);
  if (it == lanes_.end()) throw std::invalid_argument("Lanes::add: a lane it was not given");
  auto& lane = *it->second;
  if (queued_bytes_ >= ahead_bytes_) {
    if (pace_.ahead) pace_.ahead();
    // Wait until half is published: waking the reader after every message cost a context switch
    // per message (1000 a second for a 1 kHz topic). In slices: `stop` is set by a signal
    // handler, which cannot notify.
    std::unique_lock lock(mutex_);
    while (queued_bytes_ > ahead_bytes_ / 2 && !stopping()) {
      space_.wait_for(lock, std::chrono::milliseconds(100));
    }
  }
  if (stopping()) return false;
  queued_bytes_ += p.bytes.size();
  {
    std::lock_guard lock(lane.mutex);
    lane.queue.push_back(std::move(p));
  }
  lane.ready.notify_one();
  return true;
}

void Lanes::drain() { close_lanes(); }

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
  wake_on_time();  // lateness p50 on the 2-core test machine: 120 us with the default 50 us slack
  for (;;) {
    Pending p;
    {
      std::unique_lock lock(lane.mutex);
      lane.ready.wait(lock, [&] { return cancelled_ || !lane.queue.empty() || lane.closing; });
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
    // The reader waits for the queue to fall to half: wake it when this message crosses that.
    const auto before = queued_bytes_.fetch_sub(size);
    const auto crossed = [&](std::size_t mark) { return before > mark && before - size <= mark; };
    if (stopping() || crossed(ahead_bytes_ / 2)) {
      std::lock_guard lock(mutex_);
      space_.notify_all();
    }
    if (crossed(ahead_bytes_ / 4) && reading_ && pace_.behind) pace_.behind();
  }
}

}  // namespace oscar::replay
