#pragma once
/// @file The plain cue types (oscar/plain_cues.idl, docs/zero_copy.md) as cue types: PlainBool,
/// PlainLineSeg3DSeq and PlainGvImage, whose header is a PlainCueHeader of fixed size (8 stamps
/// with their count, a 64-character source, seq). Only zero-copy and benchmark code includes
/// this header; kernels use `Output<oscar::PlainGvImage>` and `Input<...>` as with any cue type.

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>

#include <oscar/plain_cues.h>
#include <oscar/plain_cuesPubSubTypes.h>

#include "oscar/cue.hpp"

OSCAR_DECLARE_CUE_TYPE(oscar, PlainBool)
OSCAR_DECLARE_CUE_TYPE(oscar, PlainLineSeg3DSeq)
OSCAR_DECLARE_CUE_TYPE(oscar, PlainGvImage)

namespace oscar {

/// Stamps a PlainCueHeader holds (its `stamps` array).
inline constexpr std::size_t kMaxPlainStamps = 8;
/// Characters of a source a PlainCueHeader holds: its `source` array less the terminating NUL.
/// An output of a plain type whose address ("<kernel>/<channel>") is longer is refused when it
/// is declared.
inline constexpr std::size_t kMaxPlainSourceLength = 63;

/// The first stamp of a plain header (its generation time), or 0 if it has none.
inline std::int64_t generation_stamp(const PlainCueHeader& h) {
  return h.stamp_count() == 0 ? 0 : static_cast<std::int64_t>(h.stamps()[0]);
}

/// Appends a stamp to a plain header. A header holds 8: once they are full, the newest stamp
/// overwrites the last slot, so the generation stamp (the first) and the newest stage's stamp
/// (the last) stay right (and with them the end-to-end latency); the stage stamped before is
/// lost.
inline void append_stamp(PlainCueHeader& h, std::int64_t stamp) {
  const std::size_t count = std::min<std::size_t>(h.stamp_count(), kMaxPlainStamps);
  const std::size_t slot = std::min(count, kMaxPlainStamps - 1);
  h.stamps()[slot] = static_cast<unsigned long long>(stamp);
  h.stamp_count(static_cast<std::uint32_t>(slot + 1));
}

/// The source of a plain header: its characters up to the first NUL (all 64 if there is none).
inline std::string source_of(const PlainCueHeader& h) {
  const auto& chars = h.source();
  return std::string(chars.data(), std::find(chars.begin(), chars.end(), '\0') - chars.begin());
}

/// Sets the source of a plain header, NUL-terminated; cut to kMaxPlainSourceLength characters.
inline void set_source(PlainCueHeader& h, const std::string& source) {
  auto& chars = h.source();
  chars.fill('\0');
  std::memcpy(chars.data(), source.data(), std::min(source.size(), kMaxPlainSourceLength));
}

template <>
struct CueHeaderForm<PlainCueHeader> {
  static constexpr CueHeaderLayout kLayout = CueHeaderLayout::kFixed;
  static constexpr std::size_t kMaxSourceLength = kMaxPlainSourceLength;
  static std::int64_t generation_stamp(const PlainCueHeader& h) {
    return oscar::generation_stamp(h);
  }
  static std::size_t stamp_count(const PlainCueHeader& h) {
    return std::min<std::size_t>(h.stamp_count(), kMaxPlainStamps);
  }
  /// A stamp_count above 8 (a header filled wrongly in memory) reads as 8.
  static CueHeader read(const PlainCueHeader& h) {
    CueHeader out;
    const std::size_t count = std::min<std::size_t>(h.stamp_count(), kMaxPlainStamps);
    out.stamps().assign(h.stamps().begin(), h.stamps().begin() + count);
    out.source(source_of(h));
    out.seq(h.seq());
    return out;
  }
  static std::int64_t complete(PlainCueHeader& h, std::uint64_t seq, const std::string& source,
                               const std::function<std::int64_t()>& clock) {
    h.seq(seq);
    set_source(h, source);
    if (h.stamp_count() != 0) return generation_stamp(h);
    const std::int64_t now = clock();
    append_stamp(h, now);
    return now;
  }
};

/// Registers the plain types so they can be found by name; register_standard_cue_types() and
/// cue_header_layout() call it.
void register_plain_cue_types();

}  // namespace oscar
