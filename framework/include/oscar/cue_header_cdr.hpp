#pragma once
/// @file Reads the CueHeader at the start of a serialized cue without knowing the cue's type:
/// every cue type's first member is `CueHeader header` (docs/architecture.md, wire types), so
/// after the 4-byte encapsulation header come the stamps sequence, the source string and the
/// sequence number.

#include <cstdint>
#include <optional>
#include <span>

#include <oscar/cue_header.h>

namespace oscar {

/// The header of a serialized cue (encapsulation header and CDR, as on the wire), or nullopt if
/// the bytes are too short or not a CDR encapsulation.
std::optional<CueHeader> read_cue_header(std::span<const std::uint8_t> payload);

}  // namespace oscar
