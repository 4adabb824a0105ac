#include "bytes.hpp"

#include <algorithm>
#include <stdexcept>

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

namespace oscar::mcap::internal {

void Out::string_map(const std::map<std::string, std::string>& m) {
  const auto at = b_.size();
  u32(0);
  for (const auto& [k, v] : m) {
    str(k);
    str(v);
  }
  const auto n = static_cast<std::uint32_t>(b_.size() - at - 4);
  for (int i = 0; i < 4; ++i) b_[at + i] = static_cast<std::uint8_t>(n >> (8 * i));
}

void Out::u16_u64_map(const std::map<std::uint16_t, std::uint64_t>& m) {
  u32(static_cast<std::uint32_t>(m.size() * 10));
  for (const auto& [k, v] : m) {
    u16(k);
    u64(v);
  }
}

std::size_t Out::begin_record(std::uint8_t op) {
  const auto start = b_.size();
  u8(op);
  u64(0);
  return start;
}

void Out::end_record(std::size_t start) {
  const std::uint64_t n = b_.size() - start - 9;
  for (int i = 0; i < 8; ++i) b_[start + 1 + i] = static_cast<std::uint8_t>(n >> (8 * i));
}

bool In::str(std::string& v) {
  std::uint32_t n = 0;
  std::span<const std::uint8_t> s;
  if (!u32(n) || !bytes(n, s)) return false;
  v.assign(s.begin(), s.end());
  return true;
}

bool In::bytes(std::size_t n, std::span<const std::uint8_t>& v) {
  if (left() < n) return false;
  v = s_.subspan(pos_, n);
  pos_ += n;
  return true;
}

bool In::string_map(std::map<std::string, std::string>& m) {
  std::uint32_t n = 0;
  std::span<const std::uint8_t> s;
  if (!u32(n) || !bytes(n, s)) return false;
  In in(s);
  while (in.left() > 0) {
    std::string k, v;
    if (!in.str(k) || !in.str(v)) return false;
    m[k] = v;
  }
  return true;
}

bool In::u16_u64_map(std::map<std::uint16_t, std::uint64_t>& m) {
  std::uint32_t n = 0;
  std::span<const std::uint8_t> s;
  if (!u32(n) || !bytes(n, s) || n % 10 != 0) return false;
  In in(s);
  while (in.left() > 0) {
    std::uint16_t k = 0;
    std::uint64_t v = 0;
    in.u16(k);
    in.u64(v);
    m[k] = v;
  }
  return true;
}

// MCAP's CRC is zlib's (CRC-32/ISO-HDLC); zlib's implementation is several times faster than a
// byte-wise table, and the recorder and replayer checksum every byte they write or read.
std::uint32_t crc32(std::span<const std::uint8_t> data, std::uint32_t crc) {
  constexpr std::size_t kMaxPiece = 1u << 30;  // zlib takes 32-bit lengths
  for (std::size_t at = 0; at < data.size(); at += kMaxPiece) {
    const auto n = std::min(kMaxPiece, data.size() - at);
    crc = static_cast<std::uint32_t>(::crc32(crc, data.data() + at, static_cast<uInt>(n)));
  }
  return crc;
}

std::vector<std::uint8_t> compress(const std::string& compression,
                                   std::span<const std::uint8_t> data) {
  std::vector<std::uint8_t> out;
  if (compression.empty()) return {data.begin(), data.end()};
  if (compression == "zstd") {
    out.resize(ZSTD_compressBound(data.size()));
    const auto n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 1);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    out.resize(n);
    return out;
  }
  if (compression == "lz4") {
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.contentSize = data.size();
    out.resize(LZ4F_compressFrameBound(data.size(), &prefs));
    const auto n = LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), &prefs);
    if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
    out.resize(n);
    return out;
  }
  throw std::invalid_argument("unknown compression '" + compression + "'");
}

std::optional<std::span<const std::uint8_t>> uncompressed(const std::string& compression,
                                                          std::span<const std::uint8_t> data,
                                                          std::uint64_t size,
                                                          std::vector<std::uint8_t>& buffer,
                                                          std::string& error) {
  if (compression.empty()) {
    if (data.size() != size) {
      error = "uncompressed chunk holds " + std::to_string(data.size()) + " bytes, not " +
              std::to_string(size);
      return std::nullopt;
    }
    return data;
  }
  buffer.resize(size);
  if (compression == "zstd") {
    const auto n = ZSTD_decompress(buffer.data(), buffer.size(), data.data(), data.size());
    if (ZSTD_isError(n) || n != size) {
      error = ZSTD_isError(n) ? std::string("zstd: ") + ZSTD_getErrorName(n)
                              : "zstd data decompresses to " + std::to_string(n) + " bytes, not " +
                                    std::to_string(size);
      return std::nullopt;
    }
    return std::span<const std::uint8_t>(buffer);
  }
  if (compression == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION);
    std::size_t in_pos = 0, out_pos = 0, hint = 1;
    while (hint != 0 && in_pos < data.size()) {
      std::size_t in_n = data.size() - in_pos, out_n = buffer.size() - out_pos;
      hint = LZ4F_decompress(ctx, buffer.data() + out_pos, &out_n, data.data() + in_pos, &in_n,
                             nullptr);
      if (LZ4F_isError(hint)) {
        error = std::string("lz4: ") + LZ4F_getErrorName(hint);
        LZ4F_freeDecompressionContext(ctx);
        return std::nullopt;
      }
      in_pos += in_n;
      out_pos += out_n;
      if (in_n == 0 && out_n == 0) break;  // no progress: the output is full or data ended
    }
    LZ4F_freeDecompressionContext(ctx);
    if (hint != 0 || out_pos != size) {
      error = "lz4 frame is incomplete or decompresses to " + std::to_string(out_pos) +
              " bytes, not " + std::to_string(size);
      return std::nullopt;
    }
    return std::span<const std::uint8_t>(buffer);
  }
  error = "unknown compression '" + compression + "' (known: zstd, lz4, none)";
  return std::nullopt;
}

}  // namespace oscar::mcap::internal
