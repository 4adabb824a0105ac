#pragma once
// Decoders of single MCAP records from their content bytes. Each returns false if the content
// is shorter than its fields need; extra bytes at the end are allowed (spec: records may grow).

#include "bytes.hpp"
#include "oscar/mcap/records.hpp"

namespace oscar::mcap::internal {

bool parse_schema(std::span<const std::uint8_t> content, Schema& s);
bool parse_channel(std::span<const std::uint8_t> content, Channel& c);
bool parse_message(std::span<const std::uint8_t> content, MessageView& m);
bool parse_statistics(std::span<const std::uint8_t> content, Statistics& s);
bool parse_chunk_index(std::span<const std::uint8_t> content, ChunkIndex& c);

struct ChunkRecord {
  std::uint64_t message_start_time = 0, message_end_time = 0, uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;
  std::string compression;
  std::span<const std::uint8_t> records;
};
bool parse_chunk(std::span<const std::uint8_t> content, ChunkRecord& c);

/// "0x06 (Chunk)" for error messages.
std::string op_name(std::uint8_t op);

}  // namespace oscar::mcap::internal
