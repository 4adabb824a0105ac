#pragma once
/// @file The newest sample of a topic the swarm coordinator publishes (its plan, its status).

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "oscar/dds_participant.hpp"
#include "oscar/topic_io.hpp"

namespace oscar::swarm::tools {

/// The newest sample of `spec`, which the coordinator keeps for late readers or publishes every
/// second. Waits `wait` for it; a coordinator found by then (its writer matched) gets as long
/// again: on a loaded host discovery and a large sample take their time.
/// @throws std::runtime_error naming `what` ("swarm plan") and the domain: no coordinator, or
/// one that offers the topic but sent nothing (hung).
template <class T, class PubSubType>
T newest_from_coordinator(DdsParticipant& participant, const TopicSpec<T, PubSubType>& spec,
                          std::chrono::milliseconds wait, const char* what) {
  std::mutex mutex;
  std::condition_variable arrived;
  std::optional<T> newest;
  TopicReader<T, PubSubType> reader(participant, spec, [&](const T& sample, const auto&) {
    std::lock_guard lock(mutex);
    newest = sample;
    arrived.notify_all();
  });
  std::unique_lock lock(mutex);  // released before the reader goes (its callback takes it)
  const auto has_sample = [&] { return newest.has_value(); };
  if (arrived.wait_for(lock, wait, has_sample)) return *newest;
  const double seconds = std::chrono::duration<double>(wait).count();
  if (reader.matched() == 0) {
    throw std::runtime_error(fmt::format(
        "no coordinator published a {} on domain {} within {:.1f} s (does the system file have "
        "coordinator: swarm:?)",
        what, participant.domain(), seconds));
  }
  if (arrived.wait_for(lock, wait, has_sample)) return *newest;
  throw std::runtime_error(
      fmt::format("the coordinator on domain {} offers a {} but sent none within {:.1f} s (is it "
                  "hung? `oscar ps` shows its state)",
                  participant.domain(), what, 2 * seconds));
}

}  // namespace oscar::swarm::tools
