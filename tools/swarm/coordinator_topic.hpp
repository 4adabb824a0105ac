#pragma once
/// @file The newest sample of a topic the swarm coordinator publishes (its plan, its status).

#include <chrono>
#include <stdexcept>

#include <fmt/format.h>

#include "oscar/dds_participant.hpp"
#include "oscar/newest_sample.hpp"
#include "oscar/topic_io.hpp"

namespace oscar::swarm::tools {

/// The newest sample of `spec`, which the coordinator keeps for late readers or publishes every
/// second, read with newest_sample() (a coordinator found gets as long again to send it).
/// @throws std::runtime_error naming `what` ("swarm plan") and the domain: no coordinator, or
/// one that offers the topic but sent nothing (hung).
template <class T, class PubSubType>
T newest_from_coordinator(DdsParticipant& participant, const TopicSpec<T, PubSubType>& spec,
                          std::chrono::milliseconds wait, const char* what) {
  auto found = newest_sample(participant, spec, wait);
  if (found.sample) return std::move(*found.sample);
  const double seconds = std::chrono::duration<double>(wait).count();
  if (!found.writer_found) {
    throw std::runtime_error(fmt::format(
        "no coordinator published a {} on domain {} within {:.1f} s (does the system file have "
        "coordinator: swarm:?)",
        what, participant.domain(), seconds));
  }
  throw std::runtime_error(
      fmt::format("the coordinator on domain {} offers a {} but sent none within {:.1f} s (is it "
                  "hung? `oscar ps` shows its state)",
                  participant.domain(), what, 2 * seconds));
}

}  // namespace oscar::swarm::tools
