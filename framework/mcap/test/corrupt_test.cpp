// Corrupt and truncated files: each is a FormatError naming the file, the byte and the fault,
// except a data section cut short in a file without footer, which is a killed writer.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/mcap/reader.hpp"
#include "test_files.hpp"

namespace oscar::mcap {
namespace {
using testing::HasSubstr;
using testing::StartsWith;

// A complete uncompressed file of 300 messages in 4 KiB chunks; returns its bytes.
std::vector<std::uint8_t> good_file(const std::string& path) {
  {
    Writer w(path, test::options(Compression::kNone));
    test::write_messages(w, 300);
  }
  return test::read_all(path);
}

// The message of the FormatError that reading `bytes` (as a file) gives.
std::string error_of(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  test::write_all(path, bytes);
  try {
    Reader r(path);
    r.info();
    r.read_messages([](const Channel&, const MessageView&) {});
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), path);
    return e.what();
  }
  return "no error";
}

constexpr std::size_t kFirstChunk = 8 + 9 + 4 + 4 + 10;  // magic, header("", "oscar-mcap")

TEST(Corrupt, AFileWithoutMagicIsNoMcapFile) {
  const auto path = test::temp_path("nomagic");
  EXPECT_EQ(error_of(path, {'h', 'e', 'l', 'l', 'o'}),
            path +
                ": byte 0: not an MCAP file: it does not start with the MCAP magic 89 4d 43 "
                "41 50 30 0d 0a");
}

TEST(Corrupt, AFlippedByteInAChunkIsACrcMismatch) {
  const auto path = test::temp_path("flip_chunk");
  auto bytes = good_file(path);
  ASSERT_EQ(bytes[kFirstChunk], 0x06) << "the first record after the header is a chunk";
  bytes[kFirstChunk + 200] ^= 0x01;
  EXPECT_THAT(error_of(path, bytes),
              StartsWith(path + ": byte " + std::to_string(kFirstChunk) + ": chunk CRC mismatch"));
}

TEST(Corrupt, AFlippedByteInTheSummaryIsASummaryCrcMismatch) {
  const auto path = test::temp_path("flip_summary");
  auto bytes = good_file(path);
  bytes[bytes.size() - 8 - 29 - 20] ^= 0x40;  // in the summary offsets, before the footer
  EXPECT_THAT(error_of(path, bytes), HasSubstr("summary CRC mismatch"));
}

std::uint64_t le64(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint64_t n = 0;
  for (int i = 0; i < 8; ++i) n |= std::uint64_t{b[at + i]} << (8 * i);
  return n;
}

TEST(Corrupt, AWrongRecordLengthInACompleteFileIsAnError) {
  const auto path = test::temp_path("bad_length");
  auto bytes = good_file(path);
  bytes[kFirstChunk + 6] = 0x7f;  // a huge chunk length
  const auto left = le64(bytes, bytes.size() - 8 - 29 + 9) - kFirstChunk - 9;  // to the summary
  EXPECT_EQ(error_of(path, bytes), path + ": byte " + std::to_string(kFirstChunk) +
                                       ": 0x06 (Chunk) record announces " +
                                       std::to_string(le64(bytes, kFirstChunk + 1)) + " bytes, " +
                                       std::to_string(left) + " are left");
}

TEST(Corrupt, AFileEndingInsideTheHeaderIsAnError) {
  const auto path = test::temp_path("short_header");
  auto bytes = good_file(path);
  bytes.resize(20);
  EXPECT_EQ(error_of(path, bytes),
            path + ": byte 8: Header record length runs past the end of file");
}

TEST(Corrupt, ABrokenZstdFrameIsADecompressionError) {
  const auto path = test::temp_path("broken_zstd");
  {
    Writer w(path, test::options(Compression::kZstd));
    test::write_messages(w, 300);
  }
  auto bytes = test::read_all(path);
  // The chunk's records: after times, size, CRC, "zstd" and the records' length.
  const std::size_t records = kFirstChunk + 9 + 8 + 8 + 8 + 4 + 4 + 4 + 8;
  bytes[records] ^= 0xff;  // the zstd frame magic
  EXPECT_THAT(error_of(path, bytes), StartsWith(path + ": byte " + std::to_string(kFirstChunk) +
                                                ": chunk cannot be decompressed: zstd: "));
}

TEST(Truncated, AFileCutInsideAChunkIsReadUpToTheChunkBefore) {
  const auto path = test::temp_path("truncated");
  auto bytes = good_file(path);
  // Walk the top-level records to the third chunk and cut the file in its middle.
  std::size_t at = kFirstChunk, third = 0;
  for (int seen = 0; seen < 3; at += 9 + le64(bytes, at + 1)) {
    if (bytes[at] == 0x06 && ++seen == 3) third = at;
  }
  bytes.resize(third + 100);
  test::write_all(path, bytes);
  Reader r(path);
  EXPECT_FALSE(r.has_summary());
  std::uint64_t count = 0;
  const auto scan = r.read_messages([&](const Channel&, const MessageView&) { ++count; });
  EXPECT_EQ(scan.chunks, 2u);
  ASSERT_TRUE(scan.truncation);
  EXPECT_THAT(*scan.truncation,
              StartsWith("data section cut short at byte " + std::to_string(third) +
                         " (0x06 (Chunk) record announces"));
  EXPECT_GT(count, 0u);
  EXPECT_LT(count, 300u);
  const auto info = Reader(path).info();
  EXPECT_EQ(info.statistics.message_count, count);
  EXPECT_THAT(*info.recovery, HasSubstr("no footer"));
}

}  // namespace
}  // namespace oscar::mcap
