#include "side_channels.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "jpeg_encoder.hpp"
#include "json_schemas.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/idl_type_info.hpp"
#include "oscar/perception_types.hpp"
#include "oscar/plain_cue_types.hpp"

namespace oscar::bridge {
namespace {
using nlohmann::json;

// The one side channel of `topic` in schema `schema_name`, or nullopt.
std::optional<ChannelInfo> side(const std::string& topic, const std::string& type,
                                const std::string& schema_name) {
  for (auto& c : side_channels_for(topic, type)) {
    if (c.schema_name == schema_name) return c;
  }
  return std::nullopt;
}

TEST(SideChannels, DrawableCuesAndTheSystemStateHaveSomeInFoxglovesSchemas) {
  const auto image = side("oscar/cue/cam_a/image", "oscar::GvImage", "foxglove.RawImage");
  ASSERT_TRUE(image);
  EXPECT_EQ(image->topic, "foxglove/cam_a/image");
  EXPECT_EQ(image->encoding, "json");
  EXPECT_EQ(image->schema_encoding, "jsonschema");
  EXPECT_EQ(image->source, "oscar/cue/cam_a/image");
  EXPECT_EQ(json::parse(image->schema)["title"], "foxglove.RawImage");
  EXPECT_EQ(side_channels_for("oscar/cue/cam_a/image", "oscar::GvImage").size(),
            jpeg_available() ? 2u : 1u);
  if (jpeg_available()) {
    for (const auto* type : {"oscar::GvImage", "oscar::PlainGvImage", "oscar::CameraImage"}) {
      const auto jpeg = side("oscar/cue/cam_a/frame", type, "foxglove.CompressedImage");
      ASSERT_TRUE(jpeg) << type;
      EXPECT_EQ(jpeg->topic, "foxglove/cam_a/frame/compressed");
      EXPECT_EQ(jpeg->source, "oscar/cue/cam_a/frame");
      EXPECT_EQ(json::parse(jpeg->schema)["title"], "foxglove.CompressedImage");
    }
  }
  EXPECT_TRUE(side("oscar/cue/cam_p/out", "oscar::PlainGvImage", "foxglove.RawImage"));
  EXPECT_TRUE(side("oscar/cue/pose/pose", "oscar::LandmarkPose", "foxglove.PoseInFrame"));
  EXPECT_TRUE(side("oscar/cue/r10/state", "oscar::RobotState", "foxglove.SceneUpdate"));
  const auto graph = side("oscar/system/state", "oscar::SystemState", "oscar.SystemGraph");
  ASSERT_TRUE(graph);
  EXPECT_EQ(graph->topic, "foxglove/system/graph");
  EXPECT_TRUE(side_channels_for("oscar/cue/sig/out", "oscar::Bool").empty());
  EXPECT_TRUE(side_channels_for("oscar/log", "oscar::GvImage").empty()) << "only cue topics";
}

TEST(SideChannels, ConvertsASampleFromItsRawCdr) {
  GvImage image;
  image.dx(2);
  image.dy(1);
  image.image({10, 20});
  const auto cdr = idl_type_info<GvImage>().serialize(&image);
  const auto message = convert_sample("oscar::GvImage", "foxglove.RawImage", cdr);
  ASSERT_TRUE(message);
  const auto m = json::parse(*message);
  EXPECT_EQ(m["width"], 2);
  EXPECT_EQ(m["data"], "ChQ=");
  LandmarkPose invalid;
  EXPECT_FALSE(convert_sample("oscar::LandmarkPose", "foxglove.PoseInFrame",
                              idl_type_info<LandmarkPose>().serialize(&invalid)));
}

// A plain image travels over DDS as its whole array (768 x 576 bytes) whatever its size.
TEST(SideChannels, ConvertsAPlainImageFromItsRawCdr) {
  auto image = std::make_unique<PlainGvImage>();
  set_source(image->header(), "cam_p/out");
  image->dx(2);
  image->dy(1);
  image->byte_count(2);
  image->image()[0] = 10;
  image->image()[1] = 20;
  const auto cdr = idl_type_info<PlainGvImage>().serialize(image.get());
  EXPECT_GT(cdr.size(), image->image().size());
  const auto m = json::parse(*convert_sample("oscar::PlainGvImage", "foxglove.RawImage", cdr));
  EXPECT_EQ(m["width"], 2);
  EXPECT_EQ(m["frame_id"], "cam_p");
  EXPECT_EQ(m["data"], "ChQ=");
  if (jpeg_available()) {
    const auto jpeg =
        json::parse(*convert_sample("oscar::PlainGvImage", "foxglove.CompressedImage", cdr));
    EXPECT_EQ(jpeg["format"], "jpeg");
    EXPECT_EQ(jpeg["frame_id"], "cam_p");
  }
}

TEST(SideChannels, ConvertsAnImageToAJpegAtTheQualityAsked) {
  if (!jpeg_available()) GTEST_SKIP() << "this build has no libjpeg";
  GvImage image;
  image.header().source("cam/out");
  image.dx(64);
  image.dy(48);
  std::vector<std::uint8_t> pixels(64 * 48);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(i * 7);
  image.image(pixels);
  const auto cdr = idl_type_info<GvImage>().serialize(&image);
  const auto best = json::parse(
      *convert_sample("oscar::GvImage", "foxglove.CompressedImage", cdr, {.jpeg_quality = 100}));
  const auto small = json::parse(
      *convert_sample("oscar::GvImage", "foxglove.CompressedImage", cdr, {.jpeg_quality = 5}));
  EXPECT_EQ(best["format"], "jpeg");
  EXPECT_EQ(best["frame_id"], "cam");
  EXPECT_LT(small["data"].get<std::string>().size(), best["data"].get<std::string>().size());
  LandmarkPose pose;
  EXPECT_THROW(convert_sample("oscar::LandmarkPose", "foxglove.CompressedImage",
                              idl_type_info<LandmarkPose>().serialize(&pose)),
               std::runtime_error)
      << "a pose has no JPEG";
}

TEST(SideChannels, MalformedBytesAreAnErrorNamingTheType) {
  try {
    convert_sample("oscar::GvImage", "foxglove.RawImage", {0, 1, 0, 0, 9});
    FAIL() << "accepted five bytes as an image";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("malformed oscar::GvImage"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(convert_sample("oscar::Bool", "foxglove.RawImage", {0, 1, 0, 0}),
               std::runtime_error);
}

}  // namespace
}  // namespace oscar::bridge
