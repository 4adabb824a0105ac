#include "oscar/mcap/records.hpp"

namespace oscar::mcap {

std::string compression_name(Compression c) {
  switch (c) {
    case Compression::kZstd:
      return "zstd";
    case Compression::kLz4:
      return "lz4";
    case Compression::kNone:
      break;
  }
  return "";
}

Compression parse_compression(const std::string& name) {
  if (name == "zstd") return Compression::kZstd;
  if (name == "lz4") return Compression::kLz4;
  if (name == "none" || name.empty()) return Compression::kNone;
  throw std::invalid_argument("compression '" + name + "': expected zstd, lz4 or none");
}

FormatError::FormatError(const std::string& file, std::uint64_t offset, const std::string& what)
    : std::runtime_error(file + ": byte " + std::to_string(offset) + ": " + what),
      file_(file),
      offset_(offset) {}

}  // namespace oscar::mcap
