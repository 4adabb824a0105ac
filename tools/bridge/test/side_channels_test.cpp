#include "side_channels.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "json_schemas.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/idl_type_info.hpp"
#include "oscar/perception_types.hpp"

namespace oscar::bridge {
namespace {
using nlohmann::json;

TEST(SideChannels, DrawableCuesAndTheSystemStateHaveOneInFoxglovesSchemas) {
  const auto image = side_channel_for("oscar/cue/cam_a/image", "oscar::GvImage");
  ASSERT_TRUE(image);
  EXPECT_EQ(image->topic, "foxglove/cam_a/image");
  EXPECT_EQ(image->schema_name, "foxglove.RawImage");
  EXPECT_EQ(image->encoding, "json");
  EXPECT_EQ(image->schema_encoding, "jsonschema");
  EXPECT_EQ(image->source, "oscar/cue/cam_a/image");
  EXPECT_EQ(json::parse(image->schema)["title"], "foxglove.RawImage");
  EXPECT_EQ(side_channel_for("oscar/cue/pose/pose", "oscar::LandmarkPose")->schema_name,
            "foxglove.PoseInFrame");
  EXPECT_EQ(side_channel_for("oscar/cue/r10/state", "oscar::RobotState")->schema_name,
            "foxglove.SceneUpdate");
  const auto graph = side_channel_for("oscar/system/state", "oscar::SystemState");
  ASSERT_TRUE(graph);
  EXPECT_EQ(graph->topic, "foxglove/system/graph");
  EXPECT_EQ(graph->schema_name, kSystemGraphSchema);
  EXPECT_FALSE(side_channel_for("oscar/cue/sig/out", "oscar::Bool"));
  EXPECT_FALSE(side_channel_for("oscar/log", "oscar::GvImage")) << "only cue topics";
}

TEST(SideChannels, ConvertsASampleFromItsRawCdr) {
  GvImage image;
  image.dx(2);
  image.dy(1);
  image.image({10, 20});
  const auto cdr = idl_type_info<GvImage>().serialize(&image);
  const auto message = convert_sample("oscar::GvImage", cdr);
  ASSERT_TRUE(message);
  const auto m = json::parse(*message);
  EXPECT_EQ(m["width"], 2);
  EXPECT_EQ(m["data"], "ChQ=");
  LandmarkPose invalid;
  EXPECT_FALSE(
      convert_sample("oscar::LandmarkPose", idl_type_info<LandmarkPose>().serialize(&invalid)));
}

TEST(SideChannels, MalformedBytesAreAnErrorNamingTheType) {
  try {
    convert_sample("oscar::GvImage", {0, 1, 0, 0, 9});
    FAIL() << "accepted five bytes as an image";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("malformed oscar::GvImage"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(convert_sample("oscar::Bool", {0, 1, 0, 0}), std::runtime_error);
}

}  // namespace
}  // namespace oscar::bridge
