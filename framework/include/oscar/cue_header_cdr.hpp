#pragma once
// Reads the CueHeader at the start of a serialized cue without knowing the cue's type: every
// cue type's first member is `CueHeader header` (docs/architecture.md, wire types), so after the
// 4-byte encapsulation header come the stamps sequence, the source string and the sequence number.

#include <cstdint>
#include <optional>
#include <span>

namespace oscar {

struct CueHeaderFields {
  std::uint64_t generation_stamp = 0;  ///< stamps[0] in ns, 0 if there is none
  std::uint64_t seq = 0;
};

/// The header fields, or nullopt if the bytes are too short or not a CDR encapsulation.
std::optional<CueHeaderFields> read_cue_header(std::span<const std::uint8_t> payload);

}  // namespace oscar
