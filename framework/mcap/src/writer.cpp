#include "oscar/mcap/writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "bytes.hpp"

namespace oscar::mcap {
using internal::Out;

namespace {
void put_schema(Out& o, const Schema& s) {
  const auto r = o.begin_record(static_cast<std::uint8_t>(Op::kSchema));
  o.u16(s.id);
  o.str(s.name);
  o.str(s.encoding);
  o.u32(static_cast<std::uint32_t>(s.data.size()));
  o.bytes(s.data);
  o.end_record(r);
}

void put_channel(Out& o, const Channel& c) {
  const auto r = o.begin_record(static_cast<std::uint8_t>(Op::kChannel));
  o.u16(c.id);
  o.u16(c.schema_id);
  o.str(c.topic);
  o.str(c.message_encoding);
  o.string_map(c.metadata);
  o.end_record(r);
}
}  // namespace

Writer::Writer(const std::string& path, WriterOptions options)
    : path_(path), options_(std::move(options)) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) {
    throw std::runtime_error("cannot create MCAP file '" + path + "': " + std::strerror(errno));
  }
  std::vector<std::uint8_t> b(std::begin(kMagic), std::end(kMagic));
  Out o(b);
  const auto r = o.begin_record(static_cast<std::uint8_t>(Op::kHeader));
  o.str(options_.profile);
  o.str(options_.library);
  o.end_record(r);
  put(b);
  if (std::fflush(file_) != 0) {
    throw std::runtime_error("cannot write MCAP file '" + path + "': " + std::strerror(errno));
  }
}

Writer::~Writer() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor cannot report; callers who care call close() themselves.
  }
  if (file_) std::fclose(file_);
}

std::uint16_t Writer::add_schema(const std::string& name, const std::string& encoding,
                                 const std::vector<std::uint8_t>& data) {
  Schema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  Out o(chunk_);
  put_schema(o, s);
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t Writer::add_channel(std::uint16_t schema_id, const std::string& topic,
                                  const std::string& message_encoding,
                                  const std::map<std::string, std::string>& metadata) {
  if (schema_id > schemas_.size()) {
    throw std::invalid_argument("channel '" + topic + "': no schema with id " +
                                std::to_string(schema_id) + " was added");
  }
  Channel c{static_cast<std::uint16_t>(channels_.size()), schema_id, topic, message_encoding,
            metadata};
  Out o(chunk_);
  put_channel(o, c);
  channels_.push_back(std::move(c));
  return channels_.back().id;
}

void Writer::write(const MessageView& m) {
  if (!file_) throw std::logic_error("MCAP writer for '" + path_ + "' is closed");
  if (m.channel_id >= channels_.size()) {
    throw std::invalid_argument("message on unknown channel " + std::to_string(m.channel_id));
  }
  Out o(chunk_);
  const auto r = o.begin_record(static_cast<std::uint8_t>(Op::kMessage));
  o.u16(m.channel_id);
  o.u32(m.sequence);
  o.u64(m.log_time);
  o.u64(m.publish_time);
  o.bytes(m.data);
  o.end_record(r);
  chunk_index_[m.channel_id].emplace_back(m.log_time, r);
  chunk_start_ = chunk_has_messages_ ? std::min(chunk_start_, m.log_time) : m.log_time;
  chunk_end_ = chunk_has_messages_ ? std::max(chunk_end_, m.log_time) : m.log_time;
  chunk_has_messages_ = true;
  auto& st = stats_;
  st.message_start_time =
      st.message_count ? std::min(st.message_start_time, m.log_time) : m.log_time;
  st.message_end_time = st.message_count ? std::max(st.message_end_time, m.log_time) : m.log_time;
  ++st.message_count;
  ++st.channel_message_counts[m.channel_id];
  if (chunk_.size() >= options_.chunk_size_bytes) write_chunk();
}

void Writer::put(std::span<const std::uint8_t> bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw std::runtime_error("cannot write MCAP file '" + path_ + "' at byte " +
                             std::to_string(offset_) + ": " + std::strerror(errno));
  }
  offset_ += bytes.size();
  crc_ = internal::crc32(bytes, crc_);
}

void Writer::write_chunk() {
  if (chunk_.empty()) return;
  const auto compression = compression_name(options_.compression);
  const auto compressed = internal::compress(compression, chunk_);
  ChunkIndex ci;
  ci.message_start_time = chunk_has_messages_ ? chunk_start_ : 0;
  ci.message_end_time = chunk_has_messages_ ? chunk_end_ : 0;
  ci.chunk_start_offset = offset_;
  ci.compression = compression;
  ci.compressed_size = compressed.size();
  ci.uncompressed_size = chunk_.size();

  std::vector<std::uint8_t> b;
  b.reserve(compressed.size() + 64);
  Out o(b);
  const auto r = o.begin_record(static_cast<std::uint8_t>(Op::kChunk));
  o.u64(ci.message_start_time);
  o.u64(ci.message_end_time);
  o.u64(chunk_.size());
  o.u32(internal::crc32(chunk_));
  o.str(compression);
  o.u64(compressed.size());
  o.bytes(compressed);
  o.end_record(r);
  ci.chunk_length = b.size();
  for (const auto& [channel, entries] : chunk_index_) {
    ci.message_index_offsets[channel] = offset_ + b.size();
    const auto m = o.begin_record(static_cast<std::uint8_t>(Op::kMessageIndex));
    o.u16(channel);
    o.u32(static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [t, at] : entries) {
      o.u64(t);
      o.u64(at);
    }
    o.end_record(m);
  }
  ci.message_index_length = b.size() - ci.chunk_length;
  // The whole chunk and its indexes in one write, then flushed: a crash leaves whole chunks.
  put(b);
  if (std::fflush(file_) != 0) {
    throw std::runtime_error("cannot write MCAP file '" + path_ + "': " + std::strerror(errno));
  }
  chunk_indexes_.push_back(std::move(ci));
  ++stats_.chunk_count;
  chunk_.clear();
  chunk_index_.clear();
  chunk_has_messages_ = false;
}

void Writer::flush() {
  if (!file_) return;
  write_chunk();
  if (std::fflush(file_) != 0) {
    throw std::runtime_error("cannot write MCAP file '" + path_ + "': " + std::strerror(errno));
  }
}

void Writer::close() {
  if (!file_) return;
  write_chunk();
  write_summary();
  const bool ok = std::fflush(file_) == 0;
  const int error = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) {
    throw std::runtime_error("cannot finish MCAP file '" + path_ + "': " + std::strerror(error));
  }
}

void Writer::write_summary() {
  std::vector<std::uint8_t> b;
  Out o(b);
  auto r = o.begin_record(static_cast<std::uint8_t>(Op::kDataEnd));
  o.u32(crc_);
  o.end_record(r);
  put(b);

  // Summary: records grouped by opcode, each group remembered for its Summary Offset record.
  const std::uint64_t summary_start = offset_;
  b.clear();
  struct Group {
    Op op;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  const auto group = [&](Op op, auto&& body) {
    const auto at = b.size();
    body();
    if (b.size() > at) groups.push_back({op, summary_start + at, b.size() - at});
  };
  group(Op::kSchema, [&] {
    for (const auto& s : schemas_) put_schema(o, s);
  });
  group(Op::kChannel, [&] {
    for (const auto& c : channels_) put_channel(o, c);
  });
  group(Op::kStatistics, [&] {
    const auto& st = stats_;
    r = o.begin_record(static_cast<std::uint8_t>(Op::kStatistics));
    o.u64(st.message_count);
    o.u16(static_cast<std::uint16_t>(schemas_.size()));
    o.u32(static_cast<std::uint32_t>(channels_.size()));
    o.u32(0);  // attachments
    o.u32(0);  // metadata
    o.u32(st.chunk_count);
    o.u64(st.message_start_time);
    o.u64(st.message_end_time);
    o.u16_u64_map(st.channel_message_counts);
    o.end_record(r);
  });
  group(Op::kChunkIndex, [&] {
    for (const auto& ci : chunk_indexes_) {
      r = o.begin_record(static_cast<std::uint8_t>(Op::kChunkIndex));
      o.u64(ci.message_start_time);
      o.u64(ci.message_end_time);
      o.u64(ci.chunk_start_offset);
      o.u64(ci.chunk_length);
      o.u16_u64_map(ci.message_index_offsets);
      o.u64(ci.message_index_length);
      o.str(ci.compression);
      o.u64(ci.compressed_size);
      o.u64(ci.uncompressed_size);
      o.end_record(r);
    }
  });
  const std::uint64_t offsets_start = summary_start + b.size();
  for (const auto& g : groups) {
    r = o.begin_record(static_cast<std::uint8_t>(Op::kSummaryOffset));
    o.u8(static_cast<std::uint8_t>(g.op));
    o.u64(g.start);
    o.u64(g.length);
    o.end_record(r);
  }
  // Footer; its CRC covers the summary through summary_offset_start.
  o.u8(static_cast<std::uint8_t>(Op::kFooter));
  o.u64(20);  // the footer's fixed length, written before the CRC that covers it
  o.u64(summary_start);
  o.u64(offsets_start);
  o.u32(internal::crc32(b));
  o.bytes(kMagic);
  put(b);
}

}  // namespace oscar::mcap
