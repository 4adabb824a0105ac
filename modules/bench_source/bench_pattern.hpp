#pragma once
// The payloads bench_source publishes and the checksum bench_sink's `verify` compares them by:
// in one place, so that the sink can tell a cue that arrived intact from one that did not.

#include <cstdint>
#include <cstring>
#include <span>

#include <oscar/cue_types.hpp>

namespace oscar::modules::bench_pattern {

inline LineSeg3DSeq lines(int n) {
  LineSeg3DSeq cue;
  for (int i = 0; i < n; ++i) {
    LineSeg3D l;
    l.sx(i);
    l.sy(0.5 * i);
    l.sz(1.0);
    l.ex(i + 1.0);
    l.ey(0.5 * i);
    l.ez(1.0);
    cue.lines().push_back(l);
  }
  return cue;
}

inline GvImage image(int dx, int dy) {
  GvImage cue;
  cue.dx(static_cast<std::int16_t>(dx));
  cue.dy(static_cast<std::int16_t>(dy));
  cue.image().resize(static_cast<std::size_t>(dx) * static_cast<std::size_t>(dy));
  for (int y = 0; y < dy; ++y) {
    for (int x = 0; x < dx; ++x) {
      cue.image()[static_cast<std::size_t>(y) * dx + x] = static_cast<std::uint8_t>((x + y) & 0xff);
    }
  }
  return cue;
}

/// FNV-1a (64 bit), continued from `h`.
inline std::uint64_t fnv1a(std::span<const std::uint8_t> bytes,
                           std::uint64_t h = 14695981039346656037ull) {
  for (const auto b : bytes) h = (h ^ b) * 1099511628211ull;
  return h;
}

template <class T>
std::uint64_t fnv1a_of(const T& value, std::uint64_t h) {
  std::uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  return fnv1a(bytes, h);
}

/// The checksum of a cue's payload (everything but the header).
inline std::uint64_t checksum(const Bool& cue) { return fnv1a_of(cue.value(), fnv1a({})); }

inline std::uint64_t checksum(const LineSeg3DSeq& cue) {
  auto h = fnv1a_of(cue.lines().size(), fnv1a({}));
  for (const auto& l : cue.lines()) {
    for (const double v : {l.sx(), l.sy(), l.sz(), l.ex(), l.ey(), l.ez()}) h = fnv1a_of(v, h);
  }
  return h;
}

inline std::uint64_t checksum(const GvImage& cue) {
  auto h = fnv1a_of(cue.dx(), fnv1a({}));
  h = fnv1a_of(cue.dy(), h);
  return fnv1a(cue.image(), h);
}

/// The checksum bench_source's payload of the same shape has (a Bool is `true`).
inline std::uint64_t expected_checksum(const Bool&) {
  Bool b;
  b.value(true);
  return checksum(b);
}
inline std::uint64_t expected_checksum(const LineSeg3DSeq& cue) {
  return checksum(lines(static_cast<int>(cue.lines().size())));
}
inline std::uint64_t expected_checksum(const GvImage& cue) {
  return checksum(image(cue.dx(), cue.dy()));
}

}  // namespace oscar::modules::bench_pattern
