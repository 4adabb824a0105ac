#pragma once
// Side channels (docs/foxglove.md, "Side channels"): besides its raw CDR channel, a topic of a
// type Foxglove can draw gets channels with the same content in Foxglove's published schemas,
// JSON encoded — images as foxglove.RawImage and foxglove.CompressedImage (JPEG), the landmark
// pose as foxglove.PoseInFrame, robot states as foxglove.SceneUpdate — and the registry's system
// state becomes the JSON system graph. A side channel lives while its source topic does; the
// bridge converts a source sample only while some client subscribes to that side channel.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "foxglove_protocol.hpp"

namespace oscar::bridge {

/// The schema of the system graph side channel (system_graph.hpp): made by the bridge from the
/// system state, discovery and its own counters, not by convert_sample().
inline constexpr std::string_view kSystemGraphSchema = "oscar.SystemGraph";
inline constexpr std::string_view kCompressedImageSchema = "foxglove.CompressedImage";

/// How samples become side channel messages.
struct ConversionSettings {
  int jpeg_quality = 80;  ///< foxglove.CompressedImage: libjpeg's quality, 1..100
};

/// The side channels of DDS topic `topic` of IDL type `type` (ids 0: the directory numbers
/// them), none if the type has none. Cue topics oscar/cue/K/C get foxglove/K/C, images also
/// foxglove/K/C/compressed (only if this build has a JPEG encoder, jpeg_available()); the system
/// state oscar/system/state gets foxglove/system/graph.
std::vector<ChannelInfo> side_channels_for(const std::string& topic, const std::string& type);

/// The message for a side channel of schema `schema_name` of one sample of `source_type` (raw
/// CDR with its encapsulation header); nullopt if the sample has nothing to draw (e.g. a pose
/// that is not valid).
/// @throws std::runtime_error if the bytes are no valid CDR encoding of `source_type`, the type
///         has no per-sample conversion to that schema, or the encoder fails.
std::optional<std::string> convert_sample(const std::string& source_type,
                                          const std::string& schema_name,
                                          const std::vector<std::uint8_t>& cdr,
                                          const ConversionSettings& settings = {});

}  // namespace oscar::bridge
