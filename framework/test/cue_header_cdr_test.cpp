// Headers read from serialized cues of any type (what the recorder and raw inputs rely on).
#include <gtest/gtest.h>

#include "oscar/cue_header_cdr.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/perception_types.hpp"

namespace oscar {
namespace {

template <class T>
void expect_header_read(T cue) {
  cue.header().stamps({1'700'000'000'123'456'789ull, 42});
  cue.header().source("src/out");
  cue.header().seq(77);
  const auto bytes = cue_type_info<T>().serialize(&cue);
  const auto h = read_cue_header(bytes);
  ASSERT_TRUE(h) << cue_type_info<T>().name;
  EXPECT_EQ(h->stamps(), (std::vector<std::uint64_t>{1'700'000'000'123'456'789ull, 42}));
  EXPECT_EQ(h->source(), "src/out");
  EXPECT_EQ(h->seq(), 77u);
}

TEST(CueHeaderCdr, ReadsStampsSourceAndSeqOfEverySeedType) {
  expect_header_read(Bool());
  LineSeg3DSeq lines;
  lines.lines().resize(3);
  expect_header_read(lines);
  GvImage image;
  image.image().resize(100);
  expect_header_read(image);
  TagDetections tags;
  tags.detections().resize(2);
  expect_header_read(tags);
}

TEST(CueHeaderCdr, RejectsShortOrForeignPayloads) {
  EXPECT_FALSE(read_cue_header(std::vector<std::uint8_t>{0, 1, 0}));
  EXPECT_FALSE(read_cue_header(std::vector<std::uint8_t>{0, 1, 0, 0, 5, 0, 0, 0}))
      << "5 stamps announced, none present";
  EXPECT_FALSE(read_cue_header(std::vector<std::uint8_t>{7, 7, 0, 0, 0, 0, 0, 0}));
}

TEST(IdlTexts, AreSelfContainedAndKeyedByQualifiedName) {
  const auto& texts = idl_texts();
  ASSERT_TRUE(texts.count("oscar::GvImage"));
  const auto& gv = texts.at("oscar::GvImage");
  EXPECT_NE(gv.find("struct CueHeader"), std::string::npos) << "the include is flattened";
  EXPECT_EQ(gv.find("#include"), std::string::npos);
  EXPECT_TRUE(texts.count("oscar::Bool"));
  EXPECT_TRUE(texts.count("oscar::LineSeg3DSeq"));
}

TEST(IdlTexts, HoldThePerceptionTypes) {
  const auto& texts = idl_texts();
  for (const char* type : {"oscar::CameraImage", "oscar::TagDetections", "oscar::LandmarkPose"}) {
    ASSERT_TRUE(texts.count(type)) << type;
    EXPECT_NE(texts.at(type).find("struct Pose3"), std::string::npos) << type;
  }
}

}  // namespace
}  // namespace oscar
