#include "zero_copy/chunk_feed.hpp"

#include <algorithm>
#include <chrono>

#include <spdlog/spdlog.h>

namespace oscar::zero_copy {

ChunkFeed::ChunkFeed(const std::string& topic, InputPort& input, const CueTypeInfo& type)
    : input_(input),
      type_(type),
      topic_(topic),
      chunks_(topic, type.name, std::clamp<std::size_t>(input.buffer().depth(), 1, 256)),
      thread_([this](std::stop_token stop) { deliver(stop); }) {}

ChunkFeed::~ChunkFeed() {
  thread_.request_stop();
  thread_.join();
}

void ChunkFeed::deliver(std::stop_token stop) {
  // The wait is bounded so that a stop is seen; a cue wakes it at once.
  constexpr auto kWait = std::chrono::milliseconds(50);
  while (!stop.stop_requested()) {
    try {
      if (auto cue = chunks_.take(kWait)) input_.deliver_from(type_, std::move(cue));
    } catch (const std::exception& e) {
      // The input holds too many chunks (iceoryx's limit): its ring gives them back as it goes.
      spdlog::error("input {}/{}: {}: {}", input_.kernel(), input_.name(), topic_, e.what());
      std::this_thread::sleep_for(kWait);
    }
  }
}

}  // namespace oscar::zero_copy
