#include "parse.hpp"

#include <cstdio>

namespace oscar::mcap::internal {

bool parse_schema(std::span<const std::uint8_t> content, Schema& s) {
  In in(content);
  std::uint32_t n = 0;
  std::span<const std::uint8_t> data;
  if (!in.u16(s.id) || !in.str(s.name) || !in.str(s.encoding) || !in.u32(n) || !in.bytes(n, data))
    return false;
  s.data.assign(data.begin(), data.end());
  return true;
}

bool parse_channel(std::span<const std::uint8_t> content, Channel& c) {
  In in(content);
  return in.u16(c.id) && in.u16(c.schema_id) && in.str(c.topic) && in.str(c.message_encoding) &&
         in.string_map(c.metadata);
}

bool parse_message(std::span<const std::uint8_t> content, MessageView& m) {
  In in(content);
  if (!in.u16(m.channel_id) || !in.u32(m.sequence) || !in.u64(m.log_time) ||
      !in.u64(m.publish_time))
    return false;
  m.data = in.rest();
  return true;
}

bool parse_statistics(std::span<const std::uint8_t> content, Statistics& s) {
  In in(content);
  return in.u64(s.message_count) && in.u16(s.schema_count) && in.u32(s.channel_count) &&
         in.u32(s.attachment_count) && in.u32(s.metadata_count) && in.u32(s.chunk_count) &&
         in.u64(s.message_start_time) && in.u64(s.message_end_time) &&
         in.u16_u64_map(s.channel_message_counts);
}

bool parse_chunk_index(std::span<const std::uint8_t> content, ChunkIndex& c) {
  In in(content);
  return in.u64(c.message_start_time) && in.u64(c.message_end_time) &&
         in.u64(c.chunk_start_offset) && in.u64(c.chunk_length) &&
         in.u16_u64_map(c.message_index_offsets) && in.u64(c.message_index_length) &&
         in.str(c.compression) && in.u64(c.compressed_size) && in.u64(c.uncompressed_size);
}

bool parse_chunk(std::span<const std::uint8_t> content, ChunkRecord& c) {
  In in(content);
  std::uint64_t n = 0;
  return in.u64(c.message_start_time) && in.u64(c.message_end_time) &&
         in.u64(c.uncompressed_size) && in.u32(c.uncompressed_crc) && in.str(c.compression) &&
         in.u64(n) && in.bytes(n, c.records);
}

std::string op_name(std::uint8_t op) {
  static const char* const kNames[] = {
      "invalid",          "Header",     "Footer",        "Schema",         "Channel",
      "Message",          "Chunk",      "Message Index", "Chunk Index",    "Attachment",
      "Attachment Index", "Statistics", "Metadata",      "Metadata Index", "Summary Offset",
      "Data End"};
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", op);
  return std::string(hex) + " (" +
         (op < 16      ? kNames[op]
          : op >= 0x80 ? "private"
                       : "unknown") +
         ")";
}

}  // namespace oscar::mcap::internal
