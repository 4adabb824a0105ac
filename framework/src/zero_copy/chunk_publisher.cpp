#include "zero_copy/chunk_publisher.hpp"

#include <stdexcept>

#include <fmt/format.h>
#include <iceoryx_posh/popo/untyped_publisher.hpp>

#include "zero_copy/roudi.hpp"
#include "zero_copy/service.hpp"
#include "zero_copy/tsan_handoff.hpp"

namespace oscar::zero_copy {

static_assert(kMaxChunkHistory == iox::MAX_PUBLISHER_HISTORY);

namespace {
iox::popo::PublisherOptions options_for(std::size_t history) {
  if (history > kMaxChunkHistory)
    throw std::invalid_argument(
        fmt::format("zero-copy publisher history {}: at most {}", history, kMaxChunkHistory));
  iox::popo::PublisherOptions options;
  options.historyCapacity = history;
  return options;
}
}  // namespace

struct ChunkPublisher::Impl {
  Impl(const iox::capro::ServiceDescription& service, const iox::popo::PublisherOptions& options)
      : publisher(service, options) {}
  iox::popo::UntypedPublisher publisher;
};

ChunkPublisher::ChunkPublisher(const std::string& topic, const std::string& type_name,
                               std::size_t history)
    : impl_([&] {
        const AwaitingRoudi awaiting("asked for a publisher port");
        return std::make_unique<Impl>(internal::service_for(topic, type_name),
                                      options_for(history));
      }()) {}

ChunkPublisher::~ChunkPublisher() = default;

void* ChunkPublisher::loan(std::size_t bytes, std::size_t alignment) {
  auto chunk = impl_->publisher.loan(static_cast<std::uint32_t>(bytes),
                                     static_cast<std::uint32_t>(alignment));
  if (chunk.has_error()) return nullptr;
  internal::taken_over(chunk.value());  // a chunk a subscriber gave back
  return chunk.value();
}

void ChunkPublisher::publish(void* payload) {
  internal::handing_over(payload);
  impl_->publisher.publish(payload);
}

void ChunkPublisher::release(void* payload) {
  internal::handing_over(payload);
  impl_->publisher.release(payload);
}

bool ChunkPublisher::has_subscribers() const { return impl_->publisher.hasSubscribers(); }

}  // namespace oscar::zero_copy
