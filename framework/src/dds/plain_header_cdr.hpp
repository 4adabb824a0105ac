#pragma once
// The PlainCueHeader in CDR (oscar/plain_cues.idl): 8 stamps (8 bytes each), stamp_count (4),
// source (64 characters, NUL-terminated), seq (8, aligned). Read by read_cue_header() and
// checked by the wire checks (wire_bounds.cpp) with the same code.

#include <optional>
#include <string>

#include <oscar/cue_header.h>

#include "dds/cdr_cursor.hpp"

namespace oscar::internal {

/// Reads a PlainCueHeader at the cursor into `out` (if not null) and leaves the cursor after it;
/// why the bytes are no valid plain header (too short, more than 8 stamps, a source without its
/// NUL), or nullopt.
std::optional<std::string> read_plain_header(CdrCursor& cdr, CueHeader* out);

}  // namespace oscar::internal
