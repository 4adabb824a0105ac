#pragma once
// Shared by the oscar::mcap tests: temporary paths and a small recording with known content.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "oscar/mcap/writer.hpp"

namespace oscar::mcap::test {

inline std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("oscar_mcap_" + std::to_string(getpid()) + "_" + name))
      .string();
}

/// Options with 4 KiB chunks (many chunks from few messages).
inline WriterOptions options(Compression compression) {
  WriterOptions o;
  o.compression = compression;
  o.chunk_size_bytes = 4096;
  return o;
}

/// The payload of message i: i-dependent bytes of an i-dependent length.
inline std::vector<std::uint8_t> payload(std::uint32_t i) {
  std::vector<std::uint8_t> p(16 + i % 200);
  for (std::size_t k = 0; k < p.size(); ++k) p[k] = static_cast<std::uint8_t>(i * 31 + k);
  return p;
}

/// Writes `n` messages round-robin on three channels (two schemas), log time 1000 + 10 i.
inline void write_messages(Writer& w, std::uint32_t n) {
  const auto a = w.add_schema("test::A", "omgidl", {'s', 't', 'r', 'u', 'c', 't'});
  const auto b = w.add_schema("test::B", "omgidl", {});
  const std::uint16_t channels[] = {w.add_channel(a, "one", "cdr", {{"kernel", "k1"}}),
                                    w.add_channel(a, "two", "cdr"),
                                    w.add_channel(b, "three", "cdr", {{"qos", "reliable"}})};
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto p = payload(i);
    w.write({channels[i % 3], i, 1000 + 10 * std::uint64_t{i}, 500 + i, p});
  }
}

inline std::vector<std::uint8_t> read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

inline void write_all(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

}  // namespace oscar::mcap::test
