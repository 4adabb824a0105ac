// The plain cue types' header (oscar/plain_cue_types.hpp, docs/zero_copy.md): stamps, completion
// on publish, the header read from CDR without the type, and malformed plain headers refused.
#include <cstring>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dds/guarded_type.hpp"  // framework/src
#include "dds/wire_bounds.hpp"
#include "oscar/cue_header_cdr.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/plain_cue_types.hpp"
#include "oscar/raw_cdr_type.hpp"

namespace oscar {
namespace {
using eprosima::fastrtps::rtps::SerializedPayload_t;
using testing::HasSubstr;

SerializedPayload_t payload_of(const std::vector<std::uint8_t>& bytes) {
  SerializedPayload_t p(static_cast<std::uint32_t>(bytes.size()));
  std::memcpy(p.data, bytes.data(), bytes.size());
  p.length = static_cast<std::uint32_t>(bytes.size());
  return p;
}

TEST(PlainCueHeader, HoldsEightStampsThenTheNewestOverwritesTheLast) {
  PlainBool cue;
  EXPECT_EQ(generation_stamp(cue.header()), 0) << "no stamp yet";
  for (std::int64_t s = 1; s <= 8; ++s) append_stamp(cue.header(), s * 10);
  EXPECT_EQ(cue.header().stamp_count(), 8u);
  append_stamp(cue.header(), 90);
  append_stamp(cue.header(), 100);
  EXPECT_EQ(cue.header().stamp_count(), 8u);
  const auto& info = cue_type_info<PlainBool>();
  EXPECT_EQ(info.header.read(&cue).stamps(),
            (std::vector<std::uint64_t>{10, 20, 30, 40, 50, 60, 70, 100}));
  EXPECT_EQ(generation_stamp(cue.header()), 10);
  EXPECT_EQ(info.header.generation_stamp(&cue), 10);
}

TEST(PlainCueHeader, PublishingSetsSeqAndSourceAndTheGenerationStampOnlyIfThereIsNone) {
  const auto& info = cue_type_info<PlainGvImage>();
  EXPECT_EQ(info.header.layout, CueHeaderLayout::kFixed);
  EXPECT_EQ(info.header.max_source_length, 63u);
  auto cue = std::make_unique<PlainGvImage>();
  cue->header().source().fill('x');  // what was there is replaced, NUL-terminated
  const auto clock = [&] {
    EXPECT_EQ(cue->header().seq(), 7u) << "the clock is read last";
    EXPECT_EQ(source_of(cue->header()), "cam/image") << "the clock is read last";
    return 1234;
  };
  EXPECT_EQ(info.header.complete(cue.get(), 7, "cam/image", clock), 1234);
  auto h = info.header.read(cue.get());
  EXPECT_EQ(h.seq(), 7u);
  EXPECT_EQ(h.source(), "cam/image");
  EXPECT_EQ(h.stamps(), (std::vector<std::uint64_t>{1234}));
  append_stamp(cue->header(), 2000);
  const auto unused_clock = [] {
    ADD_FAILURE() << "a cue that has its generation stamp needs no clock";
    return 5678;
  };
  EXPECT_EQ(info.header.complete(cue.get(), 8, "cam/image", unused_clock), 1234)
      << "the generation stamp it has";
  EXPECT_EQ(info.header.read(cue.get()).stamps(), (std::vector<std::uint64_t>{1234, 2000}))
      << "the kernel's stamps stay";
  const std::string longest(63, 's');
  info.header.complete(cue.get(), 9, longest, [] { return 1; });
  EXPECT_EQ(info.header.read(cue.get()).source(), longest);
  EXPECT_EQ(cue->header().source()[63], '\0');
}

TEST(PlainCueTypes, AreRegisteredByNameWithTheirHeaderLayoutAndIdl) {
  EXPECT_EQ(cue_header_layout("oscar::PlainBool"), CueHeaderLayout::kFixed);
  EXPECT_EQ(cue_header_layout("oscar::PlainLineSeg3DSeq"), CueHeaderLayout::kFixed);
  EXPECT_EQ(cue_header_layout("oscar::PlainGvImage"), CueHeaderLayout::kFixed);
  EXPECT_EQ(cue_header_layout("oscar::Bool"), CueHeaderLayout::kSequences);
  EXPECT_EQ(cue_header_layout("vendor::Unknown"), CueHeaderLayout::kSequences);
  ASSERT_NE(find_cue_type("oscar::PlainGvImage"), nullptr);
  EXPECT_TRUE(idl_texts().count("oscar::PlainGvImage")) << "oscar echo decodes it";
  EXPECT_TRUE(idl_texts().count("oscar::PlainCueHeader"));
}

template <class T>
std::vector<std::uint8_t> stamped_bytes(T& cue) {
  cue.header().stamp_count(0);
  append_stamp(cue.header(), 1'700'000'000'123'456'789);
  append_stamp(cue.header(), 42);
  set_source(cue.header(), "src/out");
  cue.header().seq(77);
  return cue_type_info<T>().serialize(&cue);
}

template <class T>
void expect_plain_header_read() {
  auto cue = std::make_unique<T>();
  const auto bytes = stamped_bytes(*cue);
  const auto& name = cue_type_info<T>().name;
  const auto h = read_cue_header(name, bytes);
  ASSERT_TRUE(h) << name;
  EXPECT_EQ(h->stamps(), (std::vector<std::uint64_t>{1'700'000'000'123'456'789ull, 42})) << name;
  EXPECT_EQ(h->source(), "src/out") << name;
  EXPECT_EQ(h->seq(), 77u) << name;
  EXPECT_NE(read_cue_header(bytes, CueHeaderLayout::kSequences), h)
      << name << ": read as a CueHeader, the same bytes give no such header";
  // What the recorder and raw inputs receive: the bytes under the type's name.
  RawCdrType raw(name);
  auto payload = payload_of(bytes);
  RawCue sample;
  ASSERT_TRUE(raw.deserialize(&payload, &sample));
  EXPECT_EQ(sample.header(), *h) << name;
}

TEST(PlainCueHeaderCdr, ReadsStampsSourceAndSeqOfEachPlainTypeByItsName) {
  expect_plain_header_read<PlainBool>();
  expect_plain_header_read<PlainLineSeg3DSeq>();
  expect_plain_header_read<PlainGvImage>();
}

// The wire check of `type` refuses `bytes` with a reason holding `reason`, the type support the
// framework registers drops such a sample, and the raw header reader refuses them too unless the
// fault lies after the header.
template <class T>
void expect_refused(const std::vector<std::uint8_t>& bytes, const std::string& reason,
                    bool header_readable = false) {
  const auto& name = cue_type_info<T>().name;
  const auto check = internal::wire_check(name);
  ASSERT_NE(check, nullptr) << name;
  const auto why = check(bytes);
  ASSERT_TRUE(why) << name << " passed, expected: " << reason;
  EXPECT_THAT(*why, HasSubstr(reason));
  EXPECT_EQ(read_cue_header(name, bytes).has_value(), header_readable) << name;
  internal::GuardedType guarded(cue_type_info<T>().new_topic_type(), check);
  auto payload = payload_of(bytes);
  auto sample = std::make_unique<T>();
  EXPECT_FALSE(guarded.deserialize(&payload, sample.get())) << name;
}

TEST(PlainWireCheck, PassesWhatThePlainTypesWrite) {
  auto lines = std::make_unique<PlainLineSeg3DSeq>();
  lines->line_count(256);
  auto image = std::make_unique<PlainGvImage>();
  image->byte_count(768 * 576);
  PlainBool flag;
  EXPECT_EQ(internal::wire_check("oscar::PlainBool")(stamped_bytes(flag)), std::nullopt);
  EXPECT_EQ(internal::wire_check("oscar::PlainLineSeg3DSeq")(stamped_bytes(*lines)), std::nullopt);
  EXPECT_EQ(internal::wire_check("oscar::PlainGvImage")(stamped_bytes(*image)), std::nullopt);
}

TEST(PlainWireCheck, RefusesAHeaderClaimingMoreThanEightStamps) {
  PlainBool cue;
  auto bytes = stamped_bytes(cue);
  cue.header().stamp_count(9);
  expect_refused<PlainBool>(cue_type_info<PlainBool>().serialize(&cue),
                            "its plain header claims 9 stamps, but holds at most 8");
  ASSERT_TRUE(read_cue_header("oscar::PlainBool", bytes)) << "the same cue with 2 stamps passes";
}

TEST(PlainWireCheck, RefusesASourceWithoutItsTerminatingNul) {
  auto image = std::make_unique<PlainGvImage>();
  stamped_bytes(*image);
  image->header().source().fill('a');
  expect_refused<PlainGvImage>(cue_type_info<PlainGvImage>().serialize(image.get()),
                               "source has no terminating NUL within its 64 characters");
}

TEST(PlainWireCheck, RefusesCountsBeyondTheArraysAndSamplesEndingEarly) {
  auto image = std::make_unique<PlainGvImage>();
  image->byte_count(768 * 576 + 1);
  expect_refused<PlainGvImage>(stamped_bytes(*image),
                               "its byte_count is 442369, but it holds at most 442368", true);
  auto lines = std::make_unique<PlainLineSeg3DSeq>();
  lines->line_count(257);
  expect_refused<PlainLineSeg3DSeq>(stamped_bytes(*lines),
                                    "its line_count is 257, but it holds at most 256", true);
  PlainBool flag;
  auto bytes = stamped_bytes(flag);
  bytes.resize(4 + 100);  // into the source
  expect_refused<PlainBool>(bytes, "it ends inside the plain header's source");
}

}  // namespace
}  // namespace oscar
