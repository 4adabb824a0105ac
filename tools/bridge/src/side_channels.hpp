#pragma once
// Side channels (docs/foxglove.md, "Side channels"): besides its raw CDR channel, a topic of a
// type Foxglove can draw gets a second channel with the same content in one of Foxglove's
// published schemas, JSON encoded — images as foxglove.RawImage, the landmark pose as
// foxglove.PoseInFrame, robot states as foxglove.SceneUpdate — and the registry's system state
// becomes the JSON system graph. A side channel lives while its source topic does; the bridge
// converts a source sample only while some client subscribes to its side channel.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "foxglove_protocol.hpp"

namespace oscar::bridge {

/// The schema of the system graph side channel (system_graph.hpp): made by the bridge from the
/// system state, discovery and its own counters, not by convert_sample().
inline constexpr std::string_view kSystemGraphSchema = "oscar.SystemGraph";

/// The side channel of DDS topic `topic` of IDL type `type` (id 0: the directory numbers it),
/// or nullopt if the type has none. Cue topics oscar/cue/K/C get foxglove/K/C; the system state
/// oscar/system/state gets foxglove/system/graph.
std::optional<ChannelInfo> side_channel_for(const std::string& topic, const std::string& type);

/// The side channel message of one sample of `source_type` (raw CDR with its encapsulation
/// header); nullopt if the sample has nothing to draw (e.g. a pose that is not valid).
/// @throws std::runtime_error if the bytes are no valid CDR encoding of `source_type`, or the
///         type has no per-sample conversion.
std::optional<std::string> convert_sample(const std::string& source_type,
                                          const std::vector<std::uint8_t>& cdr);

}  // namespace oscar::bridge
