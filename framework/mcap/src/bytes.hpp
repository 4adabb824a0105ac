#pragma once
// Little-endian encoding and bounds-checked decoding of MCAP's primitive types (spec
// "Serialization"). Internal to oscar::mcap.

#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace oscar::mcap::internal {

/// Appends primitives to a byte buffer.
class Out {
 public:
  explicit Out(std::vector<std::uint8_t>& buffer) : b_(buffer) {}
  void u8(std::uint8_t v) { b_.push_back(v); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void bytes(std::span<const std::uint8_t> s) { b_.insert(b_.end(), s.begin(), s.end()); }
  void str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    b_.insert(b_.end(), s.begin(), s.end());
  }
  void string_map(const std::map<std::string, std::string>& m);
  void u16_u64_map(const std::map<std::uint16_t, std::uint64_t>& m);
  /// Starts a record: opcode and a length placeholder; finish it with end_record(start).
  std::size_t begin_record(std::uint8_t op);
  void end_record(std::size_t start);
  std::size_t size() const { return b_.size(); }

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) b_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  std::vector<std::uint8_t>& b_;
};

/// Reads primitives from a span; every read is bounds checked and reports failure as nullopt,
/// so the caller can name the field and offset in its error.
class In {
 public:
  explicit In(std::span<const std::uint8_t> s) : s_(s) {}
  bool u8(std::uint8_t& v) { return get(v, 1); }
  bool u16(std::uint16_t& v) { return get(v, 2); }
  bool u32(std::uint32_t& v) { return get(v, 4); }
  bool u64(std::uint64_t& v) { return get(v, 8); }
  bool str(std::string& v);
  bool bytes(std::size_t n, std::span<const std::uint8_t>& v);
  bool string_map(std::map<std::string, std::string>& m);
  bool u16_u64_map(std::map<std::uint16_t, std::uint64_t>& m);
  std::size_t pos() const { return pos_; }
  std::size_t left() const { return s_.size() - pos_; }
  std::span<const std::uint8_t> rest() const { return s_.subspan(pos_); }

 private:
  template <class T>
  bool get(T& v, std::size_t n) {
    if (left() < n) return false;
    std::uint64_t x = 0;
    for (std::size_t i = 0; i < n; ++i) x |= static_cast<std::uint64_t>(s_[pos_ + i]) << (8 * i);
    v = static_cast<T>(x);
    pos_ += n;
    return true;
  }
  std::span<const std::uint8_t> s_;
  std::size_t pos_ = 0;
};

/// CRC-32 (ISO-HDLC, as zlib), continued from `crc` (0 to start).
std::uint32_t crc32(std::span<const std::uint8_t> data, std::uint32_t crc = 0);

/// Compresses `data` with `compression` ("zstd", "lz4" or "").
std::vector<std::uint8_t> compress(const std::string& compression,
                                   std::span<const std::uint8_t> data);
/// A chunk's `size` bytes of records: `data` itself when uncompressed (""; no copy), else `data`
/// decompressed into `buffer` (one buffer for all chunks of a scan). nullopt with `error` set if
/// that fails.
std::optional<std::span<const std::uint8_t>> uncompressed(const std::string& compression,
                                                          std::span<const std::uint8_t> data,
                                                          std::uint64_t size,
                                                          std::vector<std::uint8_t>& buffer,
                                                          std::string& error);

}  // namespace oscar::mcap::internal
