#include "oscar/cue_header_cdr.hpp"

#include <algorithm>
#include <string>

#include <fmt/format.h>

#include "dds/cdr_cursor.hpp"
#include "dds/plain_header_cdr.hpp"

namespace oscar {
namespace internal {

std::optional<std::string> read_plain_header(CdrCursor& cdr, CueHeader* out) {
  constexpr std::uint64_t kStamps = 8, kSourceBytes = 64;
  std::uint64_t stamps[kStamps] = {}, count = 0, seq = 0;
  for (auto& stamp : stamps) {
    if (!cdr.read(8, stamp)) return "it ends inside the plain header's stamps";
  }
  if (!cdr.read(4, count)) return "it ends before the plain header's stamp count";
  if (count > kStamps) {
    return fmt::format("its plain header claims {} stamps, but holds at most {}", count, kStamps);
  }
  if (cdr.left() < kSourceBytes) return "it ends inside the plain header's source";
  const auto* chars = reinterpret_cast<const char*>(cdr.here());
  const auto* nul = std::find(chars, chars + kSourceBytes, '\0');
  if (nul == chars + kSourceBytes) {
    return "its plain header's source has no terminating NUL within its 64 characters";
  }
  std::string source(chars, nul);
  cdr.skip(kSourceBytes);
  if (!cdr.read(8, seq)) return "it ends before the plain header's sequence number";
  if (out) {
    out->stamps().assign(stamps, stamps + count);
    out->source(std::move(source));
    out->seq(seq);
  }
  return std::nullopt;
}

}  // namespace internal

namespace {

std::optional<CueHeader> read_sequences_header(internal::CdrCursor& cdr) {
  CueHeader h;
  std::uint64_t stamps = 0, stamp = 0, source_length = 0, seq = 0;
  // A stamp takes 8 bytes: a count the bytes left cannot hold is refused before reserving.
  if (!cdr.read(4, stamps) || stamps > cdr.left() / 8) return std::nullopt;
  h.stamps().reserve(stamps);
  for (std::uint64_t i = 0; i < stamps; ++i) {
    if (!cdr.read(8, stamp)) return std::nullopt;
    h.stamps().push_back(stamp);
  }
  // The length counts the terminating NUL.
  if (!cdr.read(4, source_length) || source_length > cdr.left()) return std::nullopt;
  if (source_length > 0) {
    const auto* chars = reinterpret_cast<const char*>(cdr.here());
    h.source(std::string(chars, source_length - (chars[source_length - 1] == '\0' ? 1 : 0)));
  }
  cdr.skip(source_length);
  if (!cdr.read(8, seq)) return std::nullopt;
  h.seq(seq);
  return h;
}

}  // namespace

std::optional<CueHeader> read_cue_header(std::span<const std::uint8_t> payload,
                                         CueHeaderLayout layout) {
  auto cdr = internal::CdrCursor::open(payload);
  if (!cdr) return std::nullopt;
  if (layout == CueHeaderLayout::kSequences) return read_sequences_header(*cdr);
  CueHeader h;
  if (internal::read_plain_header(*cdr, &h)) return std::nullopt;
  return h;
}

std::optional<CueHeader> read_cue_header(const std::string& type_name,
                                         std::span<const std::uint8_t> payload) {
  return read_cue_header(payload, cue_header_layout(type_name));
}

}  // namespace oscar
