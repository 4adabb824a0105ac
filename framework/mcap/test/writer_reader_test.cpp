// Writer and Reader round trips, the summary, and recovery of a file whose writer never closed.
#include <gtest/gtest.h>

#include "oscar/mcap/reader.hpp"
#include "test_files.hpp"

namespace oscar::mcap {
namespace {
using test::payload;
using test::temp_path;

class RoundTrip : public testing::TestWithParam<Compression> {};

TEST_P(RoundTrip, EveryMessageComesBackWithItsChannelTimesAndBytes) {
  const auto path = temp_path("roundtrip_" + compression_name(GetParam()));
  {
    Writer w(path, test::options(GetParam()));
    test::write_messages(w, 1000);
    w.close();
  }
  Reader r(path);
  EXPECT_TRUE(r.has_summary());
  std::uint32_t i = 0;
  const auto scan = r.read_messages([&](const Channel& c, const MessageView& m) {
    const std::string topics[] = {"one", "two", "three"};
    EXPECT_EQ(c.topic, topics[i % 3]);
    EXPECT_EQ(m.sequence, i);
    EXPECT_EQ(m.log_time, 1000 + 10 * i);
    EXPECT_EQ(m.publish_time, 500 + i);
    const auto p = payload(i);
    EXPECT_TRUE(std::equal(m.data.begin(), m.data.end(), p.begin(), p.end())) << "message " << i;
    ++i;
  });
  EXPECT_EQ(i, 1000u);
  EXPECT_TRUE(scan.complete);
  EXPECT_FALSE(scan.truncation);
  EXPECT_GT(scan.chunks, 10u) << "4 KiB chunks";
}

TEST_P(RoundTrip, TheSummaryHoldsSchemasChannelsStatisticsAndCompression) {
  const auto path = temp_path("summary_" + compression_name(GetParam()));
  {
    Writer w(path, test::options(GetParam()));
    test::write_messages(w, 300);
  }  // the destructor closes
  Reader r(path);
  const auto info = r.info();
  EXPECT_TRUE(info.from_summary);
  EXPECT_FALSE(info.recovery);
  EXPECT_EQ(info.library, "oscar-mcap");
  ASSERT_EQ(info.schemas.size(), 2u);
  EXPECT_EQ(info.schemas.at(1).name, "test::A");
  EXPECT_EQ(info.schemas.at(1).encoding, "omgidl");
  ASSERT_EQ(info.channels.size(), 3u);
  EXPECT_EQ(info.channels.at(0).metadata.at("kernel"), "k1");
  EXPECT_EQ(info.channels.at(2).schema_id, 2);
  EXPECT_EQ(info.statistics.message_count, 300u);
  EXPECT_EQ(info.statistics.channel_message_counts.at(1), 100u);
  EXPECT_EQ(info.statistics.message_start_time, 1000u);
  EXPECT_EQ(info.statistics.message_end_time, 1000u + 10 * 299);
  EXPECT_EQ(info.compressions, std::set<std::string>{compression_name(GetParam())});
}

INSTANTIATE_TEST_SUITE_P(Compressions, RoundTrip,
                         testing::Values(Compression::kNone, Compression::kZstd, Compression::kLz4),
                         [](const auto& p) {
                           return p.param == Compression::kNone ? std::string("none")
                                                                : compression_name(p.param);
                         });

TEST(Reader, AnEmptyFileHasNoMessagesAndAValidSummary) {
  const auto path = temp_path("empty");
  Writer(path).close();
  Reader r(path);
  const auto info = r.info();
  EXPECT_TRUE(info.from_summary);
  EXPECT_EQ(info.statistics.message_count, 0u);
  EXPECT_TRUE(r.read_messages([](const Channel&, const MessageView&) {}).complete);
}

TEST(Reader, AFileWhoseWriterNeverClosedIsReadUpToTheLastCompleteChunk) {
  const auto path = temp_path("open_writer");
  const auto copy = temp_path("open_writer_copy");
  Writer w(path, test::options(Compression::kZstd));
  test::write_messages(w, 500);
  // What is on disk now, as a killed writer would leave it: whole chunks, no summary.
  std::filesystem::copy_file(path, copy, std::filesystem::copy_options::overwrite_existing);
  const auto on_disk = w.message_count();
  Reader r(copy);
  EXPECT_FALSE(r.has_summary());
  ASSERT_TRUE(r.missing_summary());
  EXPECT_NE(r.missing_summary()->find("no footer"), std::string::npos);
  const auto info = r.info();
  EXPECT_FALSE(info.from_summary);
  ASSERT_TRUE(info.recovery);
  EXPECT_NE(info.recovery->find("scanned the data section"), std::string::npos);
  EXPECT_GT(info.statistics.message_count, 400u);
  EXPECT_LT(info.statistics.message_count, on_disk) << "the open chunk is not on disk yet";
  EXPECT_EQ(info.channels.size(), 3u);
  EXPECT_EQ(info.compressions, std::set<std::string>{"zstd"});
  w.flush();
  std::filesystem::copy_file(path, copy, std::filesystem::copy_options::overwrite_existing);
  EXPECT_EQ(Reader(copy).info().statistics.message_count, 500u) << "flush() writes the open chunk";
}

TEST(Writer, RejectsAChannelOnAnUnknownSchemaAndAMessageOnAnUnknownChannel) {
  Writer w(temp_path("unknown_ids"));
  EXPECT_THROW(w.add_channel(3, "t", "cdr"), std::invalid_argument);
  EXPECT_THROW(w.write({7, 0, 0, 0, {}}), std::invalid_argument);
}

TEST(Writer, AnUnwritablePathIsAClearError) {
  try {
    Writer w("/nonexistent_dir/x.mcap");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "cannot create MCAP file '/nonexistent_dir/x.mcap': No such file or directory");
  }
}

TEST(Writer, AFullDiskIsAClearError) {
  // /dev/full accepts the open and fails every write with ENOSPC.
  try {
    Writer w("/dev/full");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "cannot write MCAP file '/dev/full': No space left on device");
  }
}

TEST(Compression, NamesParseAndUnknownOnesAreRejected) {
  EXPECT_EQ(parse_compression("lz4"), Compression::kLz4);
  EXPECT_EQ(parse_compression("none"), Compression::kNone);
  try {
    parse_compression("gzip");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "compression 'gzip': expected zstd, lz4 or none");
  }
}

}  // namespace
}  // namespace oscar::mcap
