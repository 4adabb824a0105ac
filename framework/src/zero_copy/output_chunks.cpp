#include "zero_copy/output_chunks.hpp"

#include <mutex>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "zero_copy/chunk_publisher.hpp"

namespace oscar::zero_copy {

struct OutputChunks::Publisher {
  Publisher(const std::string& topic, const std::string& type_name, std::size_t history)
      : chunks(topic, type_name, history) {}
  // iceoryx's publisher is not thread-safe; a loan dropped in publish() gives its chunk back
  // under the same lock.
  std::recursive_mutex mutex;
  ChunkPublisher chunks;
};

// The deleter of a loan: gives the chunk back unless it was published.
struct OutputChunks::ReturnLoan {
  std::shared_ptr<Publisher> publisher;
  bool published = false;
  void operator()(void* payload) const {
    if (published) return;
    std::lock_guard lock(publisher->mutex);
    publisher->chunks.release(payload);
  }
};

OutputChunks::OutputChunks(const std::string& topic, const CueTypeInfo& type, std::size_t history)
    : publisher_(std::make_shared<Publisher>(topic, type.name, history)),
      own_(topic, type.name, 2),
      type_(type),
      topic_(topic) {
  if (!type.memory.plain) {
    throw std::invalid_argument(fmt::format("{}: cue type {} is not plain", topic, type.name));
  }
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (!own_.subscribed() && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

OutputChunks::~OutputChunks() = default;

std::shared_ptr<void> OutputChunks::loan() {
  std::lock_guard lock(publisher_->mutex);
  void* chunk = publisher_->chunks.loan(type_.memory.size, type_.memory.alignment);
  if (!chunk) return nullptr;
  type_.memory.construct_at(chunk);
  return std::shared_ptr<void>(chunk, ReturnLoan{publisher_, false});
}

std::shared_ptr<const void> OutputChunks::publish(std::shared_ptr<const void> cue) {
  std::lock_guard lock(publisher_->mutex);
  // Until RouDi has connected the output's own subscriber, a published chunk could not be taken
  // back: the cue stays the output's, and the host's other processes get a copy. Once connected
  // it stays so (a process whose RouDi goes away ends), and is not asked again.
  if (!own_subscribed_) own_subscribed_ = own_.subscribed();
  const bool take_back = own_subscribed_;
  auto* loan = std::get_deleter<ReturnLoan>(cue);
  void* chunk = nullptr;
  if (take_back && loan && loan->publisher == publisher_ && cue.use_count() == 1) {
    loan->published = true;  // the chunk is RouDi's from now on
    chunk = const_cast<void*>(cue.get());
  } else {
    chunk = publisher_->chunks.loan(type_.memory.size, type_.memory.alignment);
    if (!chunk) {
      if (!exhausted_said_) {
        spdlog::error(
            "{}: RouDi has no chunk left for a {} cue: this host's zero-copy consumers miss "
            "it (give the system's zero_copy more chunks)",
            topic_, type_.name);
        exhausted_said_ = true;
      }
      return cue;
    }
    type_.memory.copy_to(cue.get(), chunk);
  }
  publisher_->chunks.publish(chunk);
  if (!take_back) return cue;
  auto published = own_.take(std::chrono::nanoseconds(0));
  if (!published) {  // published to RouDi's queue synchronously: this does not happen
    throw std::logic_error(topic_ + ": the output's own subscriber did not get its chunk");
  }
  return published;
}

}  // namespace oscar::zero_copy
