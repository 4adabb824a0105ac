#include "dds/wire_bounds.hpp"

#include <fmt/format.h>

#include "dds/cdr_cursor.hpp"
#include "dds/plain_header_cdr.hpp"
#include "oscar/cue.hpp"

namespace oscar::internal {
namespace {

// Reads a sequence's count and checks that the bytes left can hold that many elements of at
// least `element_bytes` each: a necessary condition for a valid sample, checked before anything
// is allocated for them. Leaves the cursor at the first element, aligned for its first value
// (`element_align` bytes).
std::optional<std::string> check_count(CdrCursor& cdr, std::uint64_t element_bytes,
                                       std::size_t element_align, const char* what,
                                       std::uint64_t& count) {
  if (!cdr.read(4, count)) return fmt::format("it ends before the count of {}", what);
  if (count > 0) cdr.align(element_align);  // an empty sequence has no element to align
  if (count > cdr.left() / element_bytes) {
    return fmt::format("it claims {} {} of at least {} bytes each in {} bytes", count, what,
                       element_bytes, cdr.left());
  }
  return std::nullopt;
}

// Checks the CueHeader every cue starts with (oscar/cue_header.idl) and leaves the cursor
// after it.
std::optional<std::string> check_header(CdrCursor& cdr) {
  std::uint64_t stamps = 0, source_length = 0, seq = 0;
  if (auto why = check_count(cdr, 8, 8, "header stamps", stamps)) return why;
  cdr.skip(stamps * 8);
  if (auto why = check_count(cdr, 1, 1, "header source characters", source_length)) return why;
  cdr.skip(source_length);
  if (!cdr.read(8, seq)) return "it ends before the header's sequence number";
  return std::nullopt;
}

std::optional<std::string> check_cue(std::span<const std::uint8_t> payload) {
  auto cdr = CdrCursor::open(payload);
  if (!cdr) return "it has no CDR encapsulation";
  return check_header(*cdr);
}

// oscar::LineSeg3DSeq (oscar/bench_types.idl): the header, then a sequence of LineSeg3D, six
// doubles (48 bytes) each.
std::optional<std::string> check_line_seg_3d_seq(std::span<const std::uint8_t> payload) {
  auto cdr = CdrCursor::open(payload);
  if (!cdr) return "it has no CDR encapsulation";
  if (auto why = check_header(*cdr)) return why;
  std::uint64_t lines = 0;
  return check_count(*cdr, 48, 8, "lines", lines);
}

// A plain cue (oscar/plain_cues.idl): its arrays have fixed sizes, so nothing is allocated for
// a count; the header's stamp count and source are checked (a consumer trusts them).
std::optional<std::string> check_plain_cue(std::span<const std::uint8_t> payload) {
  auto cdr = CdrCursor::open(payload);
  if (!cdr) return "it has no CDR encapsulation";
  return read_plain_header(*cdr, nullptr);
}

// Reads a count of valid elements after the plain header and checks it against the array's
// size: a consumer indexes the array with it.
std::optional<std::string> check_plain_count(CdrCursor& cdr, std::uint64_t most, const char* what) {
  std::uint64_t count = 0;
  if (!cdr.read(4, count)) return fmt::format("it ends before its {}", what);
  if (count > most) return fmt::format("its {} is {}, but it holds at most {}", what, count, most);
  return std::nullopt;
}

// oscar::PlainLineSeg3DSeq: the plain header, line_count (at most 256), the lines.
std::optional<std::string> check_plain_line_seg_3d_seq(std::span<const std::uint8_t> payload) {
  auto cdr = CdrCursor::open(payload);
  if (!cdr) return "it has no CDR encapsulation";
  if (auto why = read_plain_header(*cdr, nullptr)) return why;
  return check_plain_count(*cdr, 256, "line_count");
}

// oscar::PlainGvImage: the plain header, dx, dy (2 bytes each), byte_count (at most 768 x 576).
std::optional<std::string> check_plain_gv_image(std::span<const std::uint8_t> payload) {
  auto cdr = CdrCursor::open(payload);
  if (!cdr) return "it has no CDR encapsulation";
  if (auto why = read_plain_header(*cdr, nullptr)) return why;
  std::uint64_t dx = 0, dy = 0;
  if (!cdr->read(2, dx) || !cdr->read(2, dy)) return "it ends before its dx and dy";
  return check_plain_count(*cdr, 768 * 576, "byte_count");
}

}  // namespace

WireCheck wire_check(const std::string& type_name) {
  if (type_name == "oscar::LineSeg3DSeq") return &check_line_seg_3d_seq;
  if (type_name == "oscar::PlainLineSeg3DSeq") return &check_plain_line_seg_3d_seq;
  if (type_name == "oscar::PlainGvImage") return &check_plain_gv_image;
  if (cue_header_layout(type_name) == CueHeaderLayout::kFixed) return &check_plain_cue;
  if (find_cue_type(type_name)) return &check_cue;
  return nullptr;
}

}  // namespace oscar::internal
