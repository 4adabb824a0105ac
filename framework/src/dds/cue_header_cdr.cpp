#include "oscar/cue_header_cdr.hpp"

#include <string>

#include "dds/cdr_cursor.hpp"

namespace oscar {

std::optional<CueHeader> read_cue_header(std::span<const std::uint8_t> payload) {
  auto cdr = internal::CdrCursor::open(payload);
  if (!cdr) return std::nullopt;
  CueHeader h;
  std::uint64_t stamps = 0, stamp = 0, source_length = 0, seq = 0;
  // A stamp takes 8 bytes: a count the bytes left cannot hold is refused before reserving.
  if (!cdr->read(4, stamps) || stamps > cdr->left() / 8) return std::nullopt;
  h.stamps().reserve(stamps);
  for (std::uint64_t i = 0; i < stamps; ++i) {
    if (!cdr->read(8, stamp)) return std::nullopt;
    h.stamps().push_back(stamp);
  }
  // The length counts the terminating NUL.
  if (!cdr->read(4, source_length) || source_length > cdr->left()) return std::nullopt;
  if (source_length > 0) {
    const auto* chars = reinterpret_cast<const char*>(cdr->here());
    h.source(std::string(chars, source_length - (chars[source_length - 1] == '\0' ? 1 : 0)));
  }
  cdr->skip(source_length);
  if (!cdr->read(8, seq)) return std::nullopt;
  h.seq(seq);
  return h;
}

}  // namespace oscar
