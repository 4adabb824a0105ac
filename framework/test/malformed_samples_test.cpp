// Samples whose bytes are no valid encoding of their type (framework/src/dds/README.md,
// "Malformed samples"): refused by the type support the framework registers, bounded before
// anything is allocated for them, counted and logged.
#include "oscar/malformed_samples.hpp"

#include <cstring>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include "dds/guarded_type.hpp"  // framework/src
#include "dds/wire_bounds.hpp"
#include "oscar/cue_header_cdr.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"

namespace oscar {
namespace {
using eprosima::fastrtps::rtps::SerializedPayload_t;
using testing::HasSubstr;

std::vector<std::uint8_t> bytes_of(const Bool& b) { return cue_type_info<Bool>().serialize(&b); }

SerializedPayload_t payload_of(const std::vector<std::uint8_t>& bytes) {
  SerializedPayload_t p(static_cast<std::uint32_t>(bytes.size()));
  std::memcpy(p.data, bytes.data(), bytes.size());
  p.length = static_cast<std::uint32_t>(bytes.size());
  return p;
}

// A Bool whose value byte (the last one) is 2: what a participant with another layout sent.
std::vector<std::uint8_t> bool_of_value_byte_2() {
  Bool b;
  b.header().source("em/out");
  b.value(true);
  auto bytes = bytes_of(b);
  EXPECT_EQ(bytes.back(), 1) << "the value is the last byte";
  bytes.back() = 2;
  return bytes;
}

// A LineSeg3DSeq of no lines whose count (its last 4 bytes) then claims one line per byte that
// follows: Fast CDR's own check (a byte per element) passes it.
std::vector<std::uint8_t> lines_claiming_a_line_per_byte(std::uint32_t extra_bytes) {
  LineSeg3DSeq s;
  auto bytes = cue_type_info<LineSeg3DSeq>().serialize(&s);
  std::memcpy(bytes.data() + bytes.size() - 4, &extra_bytes, 4);  // little endian, as written
  bytes.resize(bytes.size() + extra_bytes);
  return bytes;
}

TEST(GuardedType, RefusesABoolWhoseValueByteIsNeither0Nor1WhereTheGeneratedTypeThrows) {
  auto bytes = bool_of_value_byte_2();
  auto payload = payload_of(bytes);
  Bool sample;
  BoolPubSubType generated;
  EXPECT_ANY_THROW(generated.deserialize(&payload, &sample)) << "the premise: Fast CDR throws";
  internal::GuardedType guarded(new BoolPubSubType(), nullptr);
  EXPECT_FALSE(guarded.deserialize(&payload, &sample));
  EXPECT_STREQ(guarded.getName(), "oscar::Bool");
}

TEST(GuardedType, DecodesAValidSampleAsTheGeneratedTypeDoes) {
  Bool b;
  b.header().seq(7);
  b.value(true);
  auto payload = payload_of(bytes_of(b));
  Bool sample;
  internal::GuardedType guarded(new BoolPubSubType(), internal::wire_check("oscar::Bool"));
  ASSERT_TRUE(guarded.deserialize(&payload, &sample));
  EXPECT_TRUE(sample.value());
  EXPECT_EQ(sample.header().seq(), 7u);
}

TEST(WireCheck, RefusesALineSeg3DSeqClaimingMoreLinesThanItsBytesHold) {
  const auto check = internal::wire_check("oscar::LineSeg3DSeq");
  ASSERT_NE(check, nullptr);
  const auto why = check(lines_claiming_a_line_per_byte(4800));
  ASSERT_TRUE(why);
  EXPECT_THAT(*why, HasSubstr("claims 4800 lines of at least 48 bytes each"));
}

TEST(WireCheck, PassesLineSeg3DSeqsThatHoldWhatTheyClaim) {
  const auto check = internal::wire_check("oscar::LineSeg3DSeq");
  for (const std::size_t stamps : {0, 1, 3}) {
    for (const std::size_t lines : {0, 1, 100}) {
      LineSeg3DSeq s;
      s.header().stamps().assign(stamps, 1);
      s.header().source("lines/out");
      s.lines().resize(lines);
      const auto bytes = cue_type_info<LineSeg3DSeq>().serialize(&s);
      EXPECT_EQ(check(bytes), std::nullopt) << stamps << " stamps, " << lines << " lines";
      if (lines > 0) {  // exactly: a byte less is refused
        const std::vector<std::uint8_t> shorter(bytes.begin(), bytes.end() - 1);
        EXPECT_NE(check(shorter), std::nullopt) << stamps << " stamps, " << lines << " lines";
      }
    }
  }
}

TEST(WireCheck, RefusesACueWhoseHeaderClaimsMoreStampsThanItsBytesHold) {
  Bool b;
  b.header().stamps({1});
  auto bytes = bytes_of(b);
  const std::uint32_t claimed = static_cast<std::uint32_t>(bytes.size());
  std::memcpy(bytes.data() + 4, &claimed, 4);  // the count right after the encapsulation
  const auto why = internal::wire_check("oscar::Bool")(bytes);
  ASSERT_TRUE(why);
  EXPECT_THAT(*why, HasSubstr("header stamps of at least 8 bytes each"));
  EXPECT_FALSE(read_cue_header(bytes)) << "the raw header reader refuses it too";
}

TEST(WireCheck, HasNoneForATypeWhoseSizesItDoesNotKnow) {
  EXPECT_EQ(internal::wire_check("oscar::ModuleState"), nullptr);
}

TEST(MalformedSamples, TheFirstOnATopicIsLoggedTheNextWithinTenSecondsOnlyCounted) {
  std::ostringstream out;
  auto log = std::make_shared<spdlog::logger>(
      "malformed_test", std::make_shared<spdlog::sinks::ostream_sink_mt>(out));
  set_malformed_sample_log(log);
  // Outside a take the type support's note is counted under its type.
  for (int i = 0; i < 5; ++i) internal::note_malformed_sample("test::Kind", "a bad byte");
  set_malformed_sample_log(nullptr);
  EXPECT_EQ(malformed_sample_count("type test::Kind"), 5u);
  const auto text = out.str();
  EXPECT_THAT(text, HasSubstr("[warning] dropped a malformed sample of type test::Kind: a bad "
                              "byte; more like it are counted and reported at most every 10 s"));
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
}

}  // namespace
}  // namespace oscar
