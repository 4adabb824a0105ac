#pragma once
// The plain forms of bench_source's payloads (oscar/plain_cue_types.hpp), for the zero-copy
// constellation of `oscar bench cueflow` (docs/zero_copy.md): the same lines and pixels as the
// sequence types, and checksums equal to theirs, so that bench_sink verifies both alike.

#include <algorithm>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <oscar/plain_cue_types.hpp>

#include "bench_pattern.hpp"

namespace oscar::modules::bench_pattern {

/// PlainLineSeg3DSeq holds at most this many lines, PlainGvImage this many pixels.
inline constexpr std::size_t kPlainLines = 256, kPlainPixels = 768 * 576;

inline PlainLineSeg3DSeq plain_lines(int n) {
  if (n < 0 || static_cast<std::size_t>(n) > kPlainLines) {
    throw std::invalid_argument("a PlainLineSeg3DSeq holds 0 to 256 lines, not " +
                                std::to_string(n));
  }
  const auto seq = lines(n);
  PlainLineSeg3DSeq cue;
  cue.line_count(static_cast<std::uint32_t>(n));
  std::copy(seq.lines().begin(), seq.lines().end(), cue.lines().begin());
  return cue;
}

inline PlainGvImage plain_image(int dx, int dy) {
  const auto bytes = static_cast<std::size_t>(dx) * static_cast<std::size_t>(dy);
  if (dx < 1 || dy < 1 || bytes > kPlainPixels) {
    throw std::invalid_argument("a PlainGvImage holds at most 768 x 576 pixels, not " +
                                std::to_string(dx) + " x " + std::to_string(dy));
  }
  const auto seq = image(dx, dy);
  PlainGvImage cue;
  cue.dx(seq.dx());
  cue.dy(seq.dy());
  cue.byte_count(static_cast<std::uint32_t>(bytes));
  std::copy(seq.image().begin(), seq.image().end(), cue.image().begin());
  return cue;
}

inline std::size_t line_count(const PlainLineSeg3DSeq& cue) {
  return std::min<std::size_t>(cue.line_count(), kPlainLines);
}
inline std::size_t pixel_count(const PlainGvImage& cue) {
  return std::min<std::size_t>(cue.byte_count(), kPlainPixels);
}

inline std::uint64_t checksum(const PlainBool& cue) { return fnv1a_of(cue.value(), fnv1a({})); }

inline std::uint64_t checksum(const PlainLineSeg3DSeq& cue) {
  auto h = fnv1a_of(line_count(cue), fnv1a({}));
  for (std::size_t i = 0; i < line_count(cue); ++i) {
    const auto& l = cue.lines()[i];
    for (const double v : {l.sx(), l.sy(), l.sz(), l.ex(), l.ey(), l.ez()}) h = fnv1a_of(v, h);
  }
  return h;
}

inline std::uint64_t checksum(const PlainGvImage& cue) {
  auto h = fnv1a_of(cue.dx(), fnv1a({}));
  h = fnv1a_of(cue.dy(), h);
  return fnv1a(std::span(cue.image().data(), pixel_count(cue)), h);
}

inline std::uint64_t expected_checksum(const PlainBool&) { return expected_checksum(Bool{}); }
inline std::uint64_t expected_checksum(const PlainLineSeg3DSeq& cue) {
  return checksum(lines(static_cast<int>(line_count(cue))));
}
inline std::uint64_t expected_checksum(const PlainGvImage& cue) {
  return checksum(image(cue.dx(), cue.dy()));
}

/// The stamps a header holds, whichever its form.
inline std::size_t stamp_count(const CueHeader& h) { return h.stamps().size(); }
inline std::size_t stamp_count(const PlainCueHeader& h) {
  return std::min<std::size_t>(h.stamp_count(), kMaxPlainStamps);
}

/// What a payload's expected checksum depends on: the number of lines, the image's size.
inline std::uint64_t shape_of(const Bool&) { return 0; }
inline std::uint64_t shape_of(const PlainBool&) { return 0; }
inline std::uint64_t shape_of(const LineSeg3DSeq& cue) { return cue.lines().size(); }
inline std::uint64_t shape_of(const PlainLineSeg3DSeq& cue) { return line_count(cue); }
template <class Image>
std::uint64_t shape_of(const Image& cue) {
  return static_cast<std::uint16_t>(cue.dx()) * 65536ull + static_cast<std::uint16_t>(cue.dy());
}

/// The benchmark types bench_source and bench_sink take, by name.
inline constexpr const char* kBenchTypes[] = {"Bool",      "LineSeg3DSeq",      "GvImage",
                                              "PlainBool", "PlainLineSeg3DSeq", "PlainGvImage"};

/// Calls `f.template operator()<T>()` with the benchmark type named `name` (one of kBenchTypes).
template <class F>
decltype(auto) visit_bench_type(std::string_view name, F&& f) {
  if (name == "PlainBool") return f.template operator()<PlainBool>();
  if (name == "PlainLineSeg3DSeq") return f.template operator()<PlainLineSeg3DSeq>();
  if (name == "PlainGvImage") return f.template operator()<PlainGvImage>();
  return visit_standard_type(name, std::forward<F>(f));
}

}  // namespace oscar::modules::bench_pattern
