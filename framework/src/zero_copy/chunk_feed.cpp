#include "zero_copy/chunk_feed.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include <spdlog/spdlog.h>

namespace oscar::zero_copy {

ChunkFeed::ChunkFeed(const std::string& topic, InputPort& input, const CueTypeInfo& type, bool held)
    : ChunkFeed(
          topic, type, input.buffer().depth(), 0,
          [&input, &type](std::shared_ptr<const void> cue) {
            input.deliver_from(type, std::move(cue));
          },
          "input " + input.kernel() + "/" + input.name(), held) {}

ChunkFeed::ChunkFeed(const std::string& topic, const CueTypeInfo& type, std::size_t capacity,
                     std::size_t history, Sink sink, std::string name, bool held)
    : sink_(std::move(sink)),
      name_(std::move(name)),
      type_(type),
      topic_(topic),
      capacity_(std::clamp<std::size_t>(capacity, 1, 256)),
      chunks_(topic, type.name, capacity_, history),
      held_(held),
      thread_([this](std::stop_token stop) { deliver(stop); }) {}

ChunkFeed::~ChunkFeed() {
  thread_.request_stop();
  thread_.join();
}

std::uint64_t ChunkFeed::seq_of(const void* cue) const { return type_.header.read(cue).seq(); }

std::optional<std::uint64_t> ChunkFeed::first_held() const {
  std::lock_guard lock(mutex_);
  if (held_cues_.empty()) return std::nullopt;
  return seq_of(held_cues_.front().get());
}

void ChunkFeed::hand_over(std::optional<std::uint64_t> delivered_through) {
  std::lock_guard lock(mutex_);
  held_ = false;
  delivered_through_ = delivered_through;
  std::deque<std::shared_ptr<const void>> held;
  held.swap(held_cues_);
  for (auto& cue : held) deliver_one(std::move(cue));
}

// Under mutex_. The cues a held feed kept are the newest up to its capacity: those the replaced
// reader delivered lie within that many below its last one.
void ChunkFeed::deliver_one(std::shared_ptr<const void> cue) {
  if (held_) {
    held_cues_.push_back(std::move(cue));
    if (held_cues_.size() > capacity_) held_cues_.pop_front();
    return;
  }
  if (delivered_through_) {
    const auto seq = seq_of(cue.get());
    if (seq <= *delivered_through_ && *delivered_through_ - seq < capacity_) return;
    delivered_through_.reset();
  }
  sink_(std::move(cue));
}

void ChunkFeed::deliver(std::stop_token stop) {
  // The wait is bounded so that a stop is seen; a cue wakes it at once.
  constexpr auto kWait = std::chrono::milliseconds(50);
  while (!stop.stop_requested()) {
    try {
      if (auto cue = chunks_.take(kWait)) {
        std::lock_guard lock(mutex_);
        deliver_one(std::move(cue));
      }
    } catch (const std::exception& e) {
      // The input holds too many chunks (iceoryx's limit): its ring gives them back as it goes.
      spdlog::error("{}: {}: {}", name_, topic_, e.what());
      std::this_thread::sleep_for(kWait);
    }
  }
}

}  // namespace oscar::zero_copy
