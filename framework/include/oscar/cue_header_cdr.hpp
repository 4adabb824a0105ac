#pragma once
/// @file Reads the header at the start of a serialized cue without knowing the cue's type:
/// every cue type's first member is its header (docs/architecture.md, wire types). After the
/// 4-byte encapsulation header come either a CueHeader (the stamps sequence, the source string,
/// the sequence number) or, for the plain types (docs/zero_copy.md), a PlainCueHeader (8 stamps,
/// their count, 64 characters, the sequence number); which one, the type's name says.

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "oscar/cue.hpp"

namespace oscar {

/// The header of a serialized cue (encapsulation header and CDR, as on the wire) whose header
/// lies as `layout` says, or nullopt if the bytes are too short, not a CDR encapsulation or (a
/// plain header) claim more than 8 stamps or a source without its terminating NUL.
std::optional<CueHeader> read_cue_header(std::span<const std::uint8_t> payload,
                                         CueHeaderLayout layout = CueHeaderLayout::kSequences);

/// The same for a cue of the DDS type `type_name` (its layout: cue_header_layout()).
std::optional<CueHeader> read_cue_header(const std::string& type_name,
                                         std::span<const std::uint8_t> payload);

}  // namespace oscar
