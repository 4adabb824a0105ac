#include "oscar/cue_header_cdr.hpp"

namespace oscar {

std::optional<CueHeaderFields> read_cue_header(std::span<const std::uint8_t> payload) {
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
  CueHeaderFields h;
  std::uint64_t stamps = 0, stamp = 0, source_length = 0;
  if (!read(4, 4, stamps)) return std::nullopt;
  for (std::uint64_t i = 0; i < stamps; ++i) {
    if (!read(8, align8, stamp)) return std::nullopt;
    if (i == 0) h.generation_stamp = stamp;
  }
  if (!read(4, 4, source_length) || at + source_length > body.size()) return std::nullopt;
  at += source_length;
  if (!read(8, align8, h.seq)) return std::nullopt;
  return h;
}

}  // namespace oscar
