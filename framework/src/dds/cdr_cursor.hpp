#pragma once
// Reads primitives from a serialized sample (4-byte encapsulation header, then CDR) without
// knowing its type: what reads a cue's header from raw bytes and checks a sample's sizes before
// its type support allocates for them.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace oscar::internal {

class CdrCursor {
 public:
  /// A cursor at the start of the body, or nullopt if the bytes are too short or carry no CDR
  /// encapsulation this knows (XCDR1 or XCDR2, either endianness).
  static std::optional<CdrCursor> open(std::span<const std::uint8_t> payload) {
    if (payload.size() < 4 || payload[0] != 0) return std::nullopt;
    const std::uint8_t kind = payload[1];
    // 0/1: XCDR1 big/little endian (8-byte values aligned to 8); 6..11: XCDR2 (aligned to 4).
    if (kind > 1 && (kind < 6 || kind > 11)) return std::nullopt;
    return CdrCursor(payload.subspan(4), kind & 1, kind <= 1 ? 8 : 4);
  }

  /// Reads an unsigned value of `size` bytes (1, 2, 4 or 8) at its alignment; false past the end.
  bool read(std::size_t size, std::uint64_t& v) {
    align(size);
    if (at_ + size > body_.size()) return false;
    v = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const std::uint64_t b = body_[at_ + i];
      v |= little_ ? b << (8 * i) : b << (8 * (size - 1 - i));
    }
    at_ += size;
    return true;
  }
  /// Skips `n` bytes; false past the end.
  bool skip(std::uint64_t n) {
    if (n > left()) return false;
    at_ += static_cast<std::size_t>(n);
    return true;
  }
  /// Moves to the alignment of a value of `size` bytes.
  void align(std::size_t size) {
    const std::size_t a = size == 8 ? align8_ : size;
    at_ = (at_ + a - 1) / a * a;
  }
  /// The bytes not read yet.
  std::size_t left() const { return at_ < body_.size() ? body_.size() - at_ : 0; }
  const std::uint8_t* here() const { return body_.data() + at_; }

 private:
  CdrCursor(std::span<const std::uint8_t> body, bool little, std::size_t align8)
      : body_(body), little_(little), align8_(align8) {}
  std::span<const std::uint8_t> body_;  // alignment counts from its start
  bool little_;
  std::size_t align8_;
  std::size_t at_ = 0;
};

}  // namespace oscar::internal
