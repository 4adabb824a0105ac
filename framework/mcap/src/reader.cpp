#include "oscar/mcap/reader.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "parse.hpp"

namespace oscar::mcap {
using internal::In;
using internal::op_name;

namespace {
constexpr std::uint64_t kFooterRecord = 1 + 8 + 20;
constexpr std::uint64_t kRecordPrefix = 1 + 8;

bool magic_at(const std::uint8_t* p) { return std::memcmp(p, kMagic, sizeof kMagic) == 0; }

std::uint64_t le64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}
}  // namespace

void Reader::fail(std::uint64_t offset, const std::string& what) const {
  throw FormatError(path_, offset, what);
}

Reader::Reader(const std::string& path) : path_(path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw std::runtime_error("cannot open '" + path + "': " + std::strerror(errno));
  struct stat st {};
  fstat(fd, &st);
  size_ = static_cast<std::uint64_t>(st.st_size);
  if (size_ > 0) {
    void* p = mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) {
      const int error = errno;
      ::close(fd);
      throw std::runtime_error("cannot map '" + path + "': " + std::strerror(error));
    }
    data_ = static_cast<const std::uint8_t*>(p);
    fd_ = fd;
  } else {
    ::close(fd);
  }
  if (size_ < sizeof kMagic || !magic_at(data_)) {
    fail(0, "not an MCAP file: it does not start with the MCAP magic 89 4d 43 41 50 30 0d 0a");
  }
  // The header record must follow the magic.
  const std::uint64_t at = sizeof kMagic;
  if (size_ < at + kRecordPrefix || data_[at] != static_cast<std::uint8_t>(Op::kHeader)) {
    fail(at, size_ < at + kRecordPrefix
                 ? "file ends before the Header record"
                 : "expected the Header record (0x01), found " + op_name(data_[at]));
  }
  const auto n = le64(data_ + at + 1);
  if (n > size_ - at - kRecordPrefix) fail(at, "Header record length runs past the end of file");
  In in({data_ + at + kRecordPrefix, n});
  if (!in.str(profile_) || !in.str(library_)) fail(at, "Header record too short for its fields");
  header_end_ = at + kRecordPrefix + n;
  data_end_ = size_;
  read_footer();
}

Reader::~Reader() {
  if (data_) munmap(const_cast<std::uint8_t*>(data_), size_);
  if (fd_ >= 0) ::close(fd_);
}

bool Reader::read_at(std::uint64_t at, std::uint64_t n, std::vector<std::uint8_t>& out) const {
  out.resize(n);
  for (std::uint64_t done = 0; done < n;) {
    const auto got = ::pread(fd_, out.data() + done, n - done, static_cast<off_t>(at + done));
    if (got <= 0) return false;  // then the mapping is read instead
    done += static_cast<std::uint64_t>(got);
  }
  return true;
}

void Reader::read_footer() {
  if (size_ < header_end_ + kFooterRecord + sizeof kMagic ||
      !magic_at(data_ + size_ - sizeof kMagic)) {
    missing_summary_ =
        "no footer: the file does not end with the MCAP magic (the writer did "
        "not finish it)";
    return;
  }
  const std::uint64_t f = size_ - sizeof kMagic - kFooterRecord;
  if (data_[f] != static_cast<std::uint8_t>(Op::kFooter) || le64(data_ + f + 1) != 20) {
    fail(f, "expected the Footer record (0x02, 20 bytes) before the closing magic, found " +
                op_name(data_[f]));
  }
  has_footer_ = true;
  const auto summary_start = le64(data_ + f + 9);
  const auto offsets_start = le64(data_ + f + 17);
  std::uint32_t crc = 0;
  for (int i = 0; i < 4; ++i) crc |= static_cast<std::uint32_t>(data_[f + 25 + i]) << (8 * i);
  data_end_ = f;
  if (summary_start == 0) {
    missing_summary_ = "the file has no summary section";
    return;
  }
  if (summary_start < header_end_ || summary_start > f || offsets_start > f ||
      (offsets_start != 0 && offsets_start < summary_start)) {
    fail(f, "Footer's summary offsets (" + std::to_string(summary_start) + ", " +
                std::to_string(offsets_start) + ") lie outside the file's summary area");
  }
  if (crc != 0) {
    const auto actual = internal::crc32({data_ + summary_start, f + 25 - summary_start});
    if (actual != crc) {
      fail(summary_start, "summary CRC mismatch: footer says " + std::to_string(crc) +
                              ", the summary section has " + std::to_string(actual));
    }
  }
  data_end_ = summary_start;
  read_summary(summary_start, offsets_start ? offsets_start : f);
}

void Reader::read_summary(std::uint64_t start, std::uint64_t end) {
  FileInfo info;
  for (std::uint64_t at = start; at < end;) {
    if (end - at < kRecordPrefix) fail(at, "summary ends inside a record's opcode and length");
    const auto op = data_[at];
    const auto n = le64(data_ + at + 1);
    if (n > end - at - kRecordPrefix) {
      fail(at, op_name(op) + " record of " + std::to_string(n) + " bytes runs past the summary");
    }
    const std::span<const std::uint8_t> c{data_ + at + kRecordPrefix, n};
    bool ok = true;
    switch (static_cast<Op>(op)) {
      case Op::kSchema: {
        Schema s;
        ok = internal::parse_schema(c, s);
        info.schemas[s.id] = std::move(s);
        break;
      }
      case Op::kChannel: {
        Channel ch;
        ok = internal::parse_channel(c, ch);
        info.channels[ch.id] = std::move(ch);
        break;
      }
      case Op::kStatistics:
        ok = internal::parse_statistics(c, info.statistics);
        break;
      case Op::kChunkIndex: {
        ChunkIndex ci;
        ok = internal::parse_chunk_index(c, ci);
        info.compressions.insert(ci.compression);
        break;
      }
      default:
        break;  // other summary records are not needed here
    }
    if (!ok) fail(at, op_name(op) + " record too short for its fields");
    at += kRecordPrefix + n;
  }
  info.from_summary = true;
  summary_ = std::move(info);
}

ScanResult Reader::read_messages(const MessageFn& fn) {
  ScanResult result;
  std::uint32_t crc = internal::crc32({data_, header_end_});
  const auto truncated = [&](std::uint64_t at, const std::string& what) {
    if (has_footer_) fail(at, what);
    result.truncation = "data section cut short at byte " + std::to_string(at) + " (" + what +
                        "); read up to there";
  };
  std::vector<std::uint8_t> chunk_record, chunk_buffer;  // a chunk as read, and decompressed
  // Reads records of a chunk's uncompressed data (base = the chunk's file offset for errors).
  const auto read_records = [&](std::span<const std::uint8_t> records, std::uint64_t chunk_at) {
    In in(records);
    while (in.left() > 0) {
      const auto at = in.pos();
      std::uint8_t op = 0;
      std::uint64_t n = 0;
      std::span<const std::uint8_t> c;
      if (!in.u8(op) || !in.u64(n) || !in.bytes(n, c)) {
        fail(chunk_at, "chunk record at offset " + std::to_string(at) +
                           " of its data runs past the chunk's end");
      }
      bool ok = true;
      if (op == static_cast<std::uint8_t>(Op::kSchema)) {
        Schema s;
        ok = internal::parse_schema(c, s);
        schemas_[s.id] = std::move(s);
      } else if (op == static_cast<std::uint8_t>(Op::kChannel)) {
        Channel ch;
        ok = internal::parse_channel(c, ch);
        channels_[ch.id] = std::move(ch);
      } else if (op == static_cast<std::uint8_t>(Op::kMessage)) {
        MessageView m;
        ok = internal::parse_message(c, m);
        const auto it = channels_.find(m.channel_id);
        if (ok && it == channels_.end()) {
          fail(chunk_at, "message at offset " + std::to_string(at) +
                             " of the chunk's data is on "
                             "channel " +
                             std::to_string(m.channel_id) +
                             ", which has no Channel "
                             "record before it");
        }
        if (ok) {
          ++result.messages;
          fn(it->second, m);
        }
      }
      if (!ok) {
        fail(chunk_at, op_name(op) + " record at offset " + std::to_string(at) +
                           " of the chunk's data is too short for its fields");
      }
    }
  };
  for (std::uint64_t at = header_end_; at < data_end_;) {
    if (data_end_ - at < kRecordPrefix) {
      truncated(at, "the file ends inside a record's opcode and length");
      return result;
    }
    const auto op = data_[at];
    const auto n = le64(data_ + at + 1);
    if (n > data_end_ - at - kRecordPrefix) {
      truncated(at, op_name(op) + " record announces " + std::to_string(n) + " bytes, " +
                        std::to_string(data_end_ - at - kRecordPrefix) + " are left");
      return result;
    }
    // A chunk is read into a buffer kept between chunks rather than through the mapping: mapping
    // in a recording page by page cost a page fault per 4 KB, and on a virtual machine those
    // delayed every other thread of the process (oscar-replay's timing, docs/benchmarks.md).
    std::span<const std::uint8_t> record{data_ + at, kRecordPrefix + n};
    if (op == static_cast<std::uint8_t>(Op::kChunk) && read_at(at, record.size(), chunk_record)) {
      record = chunk_record;
    }
    const auto c = record.subspan(kRecordPrefix);
    if (op == static_cast<std::uint8_t>(Op::kDataEnd)) {
      In in(c);
      std::uint32_t expected = 0;
      if (!in.u32(expected)) fail(at, "Data End record too short for its CRC");
      if (expected != 0 && expected != crc) {
        fail(at, "data section CRC mismatch: Data End says " + std::to_string(expected) +
                     ", the data section has " + std::to_string(crc));
      }
      result.complete = true;
      return result;
    }
    if (op == static_cast<std::uint8_t>(Op::kChunk)) {
      internal::ChunkRecord chunk;
      if (!internal::parse_chunk(c, chunk)) fail(at, "Chunk record too short for its fields");
      std::string error;
      const auto records = internal::uncompressed(chunk.compression, chunk.records,
                                                  chunk.uncompressed_size, chunk_buffer, error);
      if (!records) fail(at, "chunk cannot be decompressed: " + error);
      if (chunk.uncompressed_crc != 0) {
        const auto actual = internal::crc32(*records);
        if (actual != chunk.uncompressed_crc) {
          fail(at, "chunk CRC mismatch: the record says " + std::to_string(chunk.uncompressed_crc) +
                       ", its uncompressed data has " + std::to_string(actual));
        }
      }
      ++result.chunks;
      compressions_.insert(chunk.compression);
      read_records(*records, at);
    } else if (op == static_cast<std::uint8_t>(Op::kMessage) ||
               op == static_cast<std::uint8_t>(Op::kSchema) ||
               op == static_cast<std::uint8_t>(Op::kChannel)) {
      // Records outside chunks: the same rules as inside.
      read_records({data_ + at, kRecordPrefix + n}, at);
    } else if (op == 0 || (op > 0x0F && op < 0x80) ||
               op == static_cast<std::uint8_t>(Op::kHeader) ||
               op == static_cast<std::uint8_t>(Op::kFooter)) {
      fail(at, "unexpected " + op_name(op) + " record in the data section");
    }
    crc = internal::crc32(record, crc);
    at += kRecordPrefix + n;
  }
  if (has_footer_) fail(data_end_, "the data section has no Data End record");
  result.truncation = "the data section ends at byte " + std::to_string(data_end_) +
                      " without a Data End record; read up to there";
  return result;
}

FileInfo Reader::info() {
  if (summary_) {
    FileInfo info = *summary_;
    info.profile = profile_;
    info.library = library_;
    info.file_size = size_;
    return info;
  }
  FileInfo info;
  info.profile = profile_;
  info.library = library_;
  info.file_size = size_;
  auto& st = info.statistics;
  const auto scan = read_messages([&](const Channel& c, const MessageView& m) {
    st.message_start_time =
        st.message_count ? std::min(st.message_start_time, m.log_time) : m.log_time;
    st.message_end_time = std::max(st.message_end_time, m.log_time);
    ++st.message_count;
    ++st.channel_message_counts[c.id];
  });
  st.chunk_count = static_cast<std::uint32_t>(scan.chunks);
  info.schemas = schemas_;
  info.channels = channels_;
  st.schema_count = static_cast<std::uint16_t>(schemas_.size());
  st.channel_count = static_cast<std::uint32_t>(channels_.size());
  info.compressions = compressions_;
  info.recovery = *missing_summary_ + "; scanned the data section" +
                  (scan.truncation ? ": " + *scan.truncation : ", which is complete");
  return info;
}

}  // namespace oscar::mcap
