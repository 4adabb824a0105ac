#pragma once
// Size checks a type support runs on a sample's bytes before the generated code decodes them.
// Fast CDR checks a sequence's count only against the bytes left (one byte per element), then
// resizes the vector: a sample claiming as many elements as it has bytes made the reader
// allocate sizeof(element) bytes per byte received (48 for a LineSeg3D) before failing.

#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace oscar::internal {

/// Why the bytes cannot be a sample of the type (a count the bytes left cannot hold), or
/// nullopt.
using WireCheck = std::optional<std::string> (*)(std::span<const std::uint8_t> payload);

/// The check for the type of that DDS name, or nullptr if there is none: every cue type's
/// header is checked (a CueHeader's stamps sequence; a PlainCueHeader's stamp count and source),
/// oscar::LineSeg3DSeq's lines too, and the counts of valid lines and pixels of
/// oscar::PlainLineSeg3DSeq and oscar::PlainGvImage.
WireCheck wire_check(const std::string& type_name);

}  // namespace oscar::internal
