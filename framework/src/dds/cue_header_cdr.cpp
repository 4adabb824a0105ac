#include "oscar/cue_header_cdr.hpp"

#include <string>

namespace oscar {

std::optional<CueHeader> read_cue_header(std::span<const std::uint8_t> payload) {
  if (payload.size() < 4 || payload[0] != 0) return std::nullopt;
  const std::uint8_t kind = payload[1];
  // 0/1: XCDR1 big/little endian (8-byte values aligned to 8); 6..11: XCDR2 (aligned to 4).
  if (kind > 1 && (kind < 6 || kind > 11)) return std::nullopt;
  const bool little = kind & 1;
  const std::size_t align8 = kind <= 1 ? 8 : 4;
  const auto body = payload.subspan(4);  // alignment counts from here
  std::size_t at = 0;
  const auto read = [&](std::size_t size, std::size_t align, std::uint64_t& v) {
    at = (at + align - 1) / align * align;
    if (at + size > body.size()) return false;
    v = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const std::uint64_t b = body[at + i];
      v |= little ? b << (8 * i) : b << (8 * (size - 1 - i));
    }
    at += size;
    return true;
  };
  CueHeader h;
  std::uint64_t stamps = 0, stamp = 0, source_length = 0, seq = 0;
  if (!read(4, 4, stamps) || stamps > body.size()) return std::nullopt;
  h.stamps().reserve(stamps);
  for (std::uint64_t i = 0; i < stamps; ++i) {
    if (!read(8, align8, stamp)) return std::nullopt;
    h.stamps().push_back(stamp);
  }
  // The length counts the terminating NUL.
  if (!read(4, 4, source_length) || at + source_length > body.size()) return std::nullopt;
  if (source_length > 0) {
    const auto* chars = reinterpret_cast<const char*>(body.data() + at);
    h.source(std::string(chars, source_length - (chars[source_length - 1] == '\0' ? 1 : 0)));
  }
  at += source_length;
  if (!read(8, align8, seq)) return std::nullopt;
  h.seq(seq);
  return h;
}

}  // namespace oscar
