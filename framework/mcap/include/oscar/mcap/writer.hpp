#pragma once
/// @file Writer: an indexed, chunked MCAP file (header, chunks with message indexes, summary
/// with schemas, channels, statistics and chunk indexes, summary offsets, footer).

#include <cstdio>
#include <string>
#include <vector>

#include "oscar/mcap/records.hpp"

namespace oscar::mcap {

struct WriterOptions {
  Compression compression = Compression::kZstd;
  /// A chunk is closed and written once its uncompressed records reach this size.
  std::size_t chunk_size_bytes = 1 << 20;
  std::string profile;  ///< the header's profile ("" = none)
  std::string library = "oscar-mcap";
};

/// Writes one MCAP file. Every chunk goes to the file whole and flushed, so a writer killed
/// mid-run leaves a file whose data section is readable up to the last completed chunk.
/// Splitting into several files is the caller's job (bytes_written(), message times).
class Writer {
 public:
  /// Creates (truncates) `path` and writes magic and header.
  /// @throws std::runtime_error naming the path and the system's reason if it cannot.
  Writer(const std::string& path, WriterOptions options = {});
  /// Finishes the file (close()) if that was not done; errors are swallowed here.
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// Adds a schema and returns its id (1, 2, ...).
  std::uint16_t add_schema(const std::string& name, const std::string& encoding,
                           const std::vector<std::uint8_t>& data);
  /// Adds a channel and returns its id (0, 1, ...).
  /// @throws std::invalid_argument if schema_id is neither 0 nor a schema added here.
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic,
                            const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata = {});
  /// Adds a message to the open chunk, writing the chunk when it is full.
  /// @throws std::invalid_argument for an unknown channel; std::runtime_error on I/O errors.
  void write(const MessageView& message);
  /// Writes the open chunk now (if it holds anything) and flushes it to the operating system.
  void flush();
  /// Writes the last chunk, data end, summary, summary offsets, footer and magic; closes.
  /// @throws std::runtime_error on I/O errors (naming the path).
  void close();

  const std::string& path() const { return path_; }
  /// Bytes in the file so far plus the open chunk's uncompressed records.
  std::uint64_t bytes_written() const { return offset_ + chunk_.size(); }
  std::uint64_t message_count() const { return stats_.message_count; }

 private:
  void put(std::span<const std::uint8_t> bytes);
  void write_chunk();
  void write_summary();

  std::string path_;
  WriterOptions options_;
  std::FILE* file_ = nullptr;
  std::uint64_t offset_ = 0;
  std::uint32_t crc_ = 0;  // of every byte written so far
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  Statistics stats_;
  std::vector<ChunkIndex> chunk_indexes_;
  // The open chunk: its records, time range and per-channel (log_time, offset) index.
  std::vector<std::uint8_t> chunk_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  bool chunk_has_messages_ = false;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
};

}  // namespace oscar::mcap
