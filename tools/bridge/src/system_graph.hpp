#pragma once
// The system graph as one JSON message (schema oscar.SystemGraph, tools/bridge/schemas/): what
// `oscar ps` and `oscar graph` show — every module with its host, pid, status and rate, its
// kernels with mode, parameters and wiring, every cue channel with its type, producer and
// consumers — from the registry's system state and discovery, plus what the bridge's side
// channels did (docs/foxglove.md, "The system graph").

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <oscar/registry.h>

#include "oscar/dds_participant.hpp"

namespace oscar::bridge {

/// What one side channel did so far (docs/foxglove.md, "Side channels").
struct SideChannelActivity {
  std::string topic;
  std::string source;           ///< the DDS topic it is made from
  int subscribers = 0;          ///< clients subscribed now
  std::uint64_t converted = 0;  ///< messages made from the source so far
  std::uint64_t skipped = 0;    ///< source samples with nothing to draw (e.g. an invalid pose)
};

/// The system state in the raw CDR of a sample of oscar/system/state.
/// @throws std::runtime_error if the bytes are no valid CDR encoding of oscar::SystemState.
SystemState system_state_from_cdr(const std::vector<std::uint8_t>& cdr);

/// The graph of `state`, cue channel types from `writers`, and `side_channels`.
std::string system_graph_json(
    const SystemState& state,
    const std::map<std::string, DdsParticipant::DiscoveredWriter>& writers,
    const std::vector<SideChannelActivity>& side_channels);

}  // namespace oscar::bridge
