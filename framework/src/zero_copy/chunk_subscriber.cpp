#include "zero_copy/chunk_subscriber.hpp"

#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
#include <iceoryx_posh/popo/untyped_subscriber.hpp>
#include <iceoryx_posh/popo/wait_set.hpp>

#include "zero_copy/roudi.hpp"
#include "zero_copy/service.hpp"
#include "zero_copy/tsan_handoff.hpp"

namespace oscar::zero_copy {

namespace {
iox::popo::SubscriberOptions options_for(std::size_t queue_capacity, std::size_t history) {
  if (queue_capacity == 0 || queue_capacity > iox::MAX_SUBSCRIBER_QUEUE_CAPACITY)
    throw std::invalid_argument(fmt::format("zero-copy queue capacity {}: 1 to {}", queue_capacity,
                                            iox::MAX_SUBSCRIBER_QUEUE_CAPACITY));
  iox::popo::SubscriberOptions options;
  options.queueCapacity = queue_capacity;
  options.historyRequest = history;
  return options;
}
}  // namespace

// Shared by the subscriber and every chunk it handed out: iceoryx's subscriber is not
// thread-safe, and chunks are released on whichever thread drops the last pointer.
struct ChunkSubscriber::State {
  State(const iox::capro::ServiceDescription& service, const iox::popo::SubscriberOptions& options)
      : subscriber(service, options) {
    waitset.attachState(subscriber, iox::popo::SubscriberState::HAS_DATA).or_else([](auto) {
      throw std::runtime_error("zero-copy subscriber: no room in a wait set (RouDi's limits)");
    });
  }
  ~State() { waitset.detachState(subscriber, iox::popo::SubscriberState::HAS_DATA); }

  std::mutex mutex;  // guards subscriber
  iox::popo::UntypedSubscriber subscriber;
  iox::popo::WaitSet<1> waitset;
};

ChunkSubscriber::ChunkSubscriber(const std::string& topic, const std::string& type_name,
                                 std::size_t queue_capacity, std::size_t history)
    : state_([&] {
        const AwaitingRoudi awaiting("asked for a subscriber port");
        return std::make_shared<State>(internal::service_for(topic, type_name),
                                       options_for(queue_capacity, history));
      }()) {}

ChunkSubscriber::~ChunkSubscriber() = default;

bool ChunkSubscriber::subscribed() const {
  std::lock_guard lock(state_->mutex);
  return state_->subscriber.getSubscriptionState() == iox::SubscribeState::SUBSCRIBED;
}

std::shared_ptr<const void> ChunkSubscriber::take(std::chrono::nanoseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    {
      std::lock_guard lock(state_->mutex);
      auto taken = state_->subscriber.take();
      if (!taken.has_error()) {
        internal::taken_over(taken.value());
        auto state = state_;
        return std::shared_ptr<const void>(taken.value(), [state](const void* payload) {
          internal::handing_over(payload);
          std::lock_guard release_lock(state->mutex);
          state->subscriber.release(payload);
        });
      }
      if (taken.get_error() == iox::popo::ChunkReceiveResult::TOO_MANY_CHUNKS_HELD_IN_PARALLEL)
        throw std::runtime_error(fmt::format(
            "zero-copy subscriber holds {} chunks already (iceoryx's limit): drop some cues",
            iox::MAX_CHUNKS_HELD_PER_SUBSCRIBER_SIMULTANEOUSLY));
    }
    const auto left = until - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds(0)) return nullptr;
    state_->waitset.timedWait(iox::units::Duration::fromNanoseconds(static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(left).count())));
  }
}

}  // namespace oscar::zero_copy
