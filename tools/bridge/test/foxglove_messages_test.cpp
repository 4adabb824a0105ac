#include "foxglove_messages.hpp"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "json_schema_check.hpp"
#include "json_schemas.hpp"

namespace oscar::bridge {
namespace {
using nlohmann::json;

std::vector<std::uint8_t> bytes(std::string_view s) { return {s.begin(), s.end()}; }

std::vector<std::uint8_t> from_base64(const std::string& text) {
  static const std::string kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<std::uint8_t> out;
  std::uint32_t bits = 0;
  int n = 0;
  for (const char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | static_cast<std::uint32_t>(kAlphabet.find(c));
    if ((n += 6) >= 8) {
      n -= 8;
      out.push_back(static_cast<std::uint8_t>(bits >> n));
    }
  }
  return out;
}

// What of `message` does not follow the bridge's schema `name`: a field that does not conform, or
// one the schema does not declare; "" if all does.
std::string off_schema(const std::string& name, const json& message) {
  const auto schema = json::parse(json_schema(name));
  if (auto m = test::schema_mismatch(schema, message); !m.empty()) return m;
  if (auto u = test::undeclared_field(schema, message); !u.empty()) return u + " is not declared";
  return "";
}

CueHeader header(std::uint64_t stamp_ns, const std::string& source) {
  CueHeader h;
  h.stamps({stamp_ns});
  h.source(source);
  h.seq(7);
  return h;
}

TEST(FoxgloveMessages, Base64IsRfc4648WithPadding) {
  EXPECT_EQ(base64(bytes("")), "");
  EXPECT_EQ(base64(bytes("f")), "Zg==");
  EXPECT_EQ(base64(bytes("fo")), "Zm8=");
  EXPECT_EQ(base64(bytes("foo")), "Zm9v");
  EXPECT_EQ(base64(bytes("foobar")), "Zm9vYmFy");
  const std::vector<std::uint8_t> all = {0x00, 0xff, 0xfe, 0x80, 0x7f};
  EXPECT_EQ(base64(all), "AP/+gH8=");
}

TEST(FoxgloveMessages, AGreyImageIsARawImageWithEveryPixel) {
  GvImage image;
  image.header(header(1'700'000'000'123'456'789ull, "cam_a/image"));
  image.dx(5);
  image.dy(3);
  std::vector<std::uint8_t> pixels(15);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(i * 17);
  image.image(pixels);
  const auto text = raw_image_json(image);
  ASSERT_TRUE(text);
  const auto m = json::parse(*text);
  EXPECT_EQ(off_schema("foxglove.RawImage", m), "");
  EXPECT_EQ(m["width"], 5);
  EXPECT_EQ(m["height"], 3);
  EXPECT_EQ(m["step"], 5);
  EXPECT_EQ(m["encoding"], "mono8");
  EXPECT_EQ(m["frame_id"], "cam_a");
  EXPECT_EQ(m["timestamp"], json::parse(R"({"sec":1700000000,"nsec":123456789})"));
  EXPECT_EQ(from_base64(m["data"]), pixels);
}

TEST(FoxgloveMessages, AnImageWhosePixelsDoNotFillItIsNotDrawn) {
  GvImage image;
  image.dx(4);
  image.dy(4);
  image.image(std::vector<std::uint8_t>(15));
  EXPECT_FALSE(raw_image_json(image));
  image.dx(-4);
  image.dy(-4);
  image.image(std::vector<std::uint8_t>(16));
  EXPECT_FALSE(raw_image_json(image));
}

// A plain image (the zero-copy form, docs/zero_copy.md) holds 768 x 576 pixels; its byte_count
// says how many of them are the image.
TEST(FoxgloveMessages, APlainImageIsARawImageOfItsFirstByteCountPixels) {
  auto image = std::make_unique<PlainGvImage>();  // 442 KB: not on the stack
  CueHeaderForm<PlainCueHeader>::complete(image->header(), 7, "cam_p/out",
                                          [] { return 1'700'000'000'000'000'005; });
  image->dx(4);
  image->dy(2);
  image->byte_count(8);
  for (std::size_t i = 0; i < image->image().size(); ++i) {
    image->image()[i] = static_cast<std::uint8_t>(i < 8 ? 30 + i : 255);
  }
  const auto m = json::parse(*raw_image_json(*image));
  EXPECT_EQ(off_schema("foxglove.RawImage", m), "");
  EXPECT_EQ(m["width"], 4);
  EXPECT_EQ(m["height"], 2);
  EXPECT_EQ(m["step"], 4);
  EXPECT_EQ(m["frame_id"], "cam_p");
  EXPECT_EQ(m["timestamp"], json::parse(R"({"sec":1700000000,"nsec":5})"));
  EXPECT_EQ(from_base64(m["data"]), (std::vector<std::uint8_t>{30, 31, 32, 33, 34, 35, 36, 37}))
      << "the pixels after byte_count are not the image's";

  image->byte_count(9);
  EXPECT_FALSE(raw_image_json(*image)) << "9 bytes do not make 4 x 2 pixels";
  image->dx(768);
  image->dy(577);
  image->byte_count(768 * 577);
  EXPECT_FALSE(raw_image_json(*image)) << "a byte_count beyond the image's array";
}

TEST(FoxgloveMessages, ACameraImageNamesItsCameraAsFrame) {
  CameraImage image;
  image.header(header(5, "cam_b/frame"));
  image.camera_id("cam_b");
  image.encoding("mono8");
  image.width(2);
  image.height(2);
  image.data({1, 2, 3, 4});
  const auto m = json::parse(*raw_image_json(image));
  EXPECT_EQ(off_schema("foxglove.RawImage", m), "");
  EXPECT_EQ(m["frame_id"], "cam_b");
  EXPECT_EQ(from_base64(m["data"]), (std::vector<std::uint8_t>{1, 2, 3, 4}));
}

TEST(FoxgloveMessages, TheLandmarkPoseIsAPoseInTheWorldWithItsQuaternionReordered) {
  LandmarkPose pose;
  pose.header(header(2'000'000'001ull, "pose/pose"));
  pose.valid(true);
  Pose3 p;
  p.t({0.1, -0.2, 1.5});
  p.q({0.5, 0.5, -0.5, 0.5});  // w, x, y, z
  pose.pose(p);
  const auto m = json::parse(*pose_in_frame_json(pose));
  EXPECT_EQ(off_schema("foxglove.PoseInFrame", m), "");
  EXPECT_EQ(m["frame_id"], "world");
  EXPECT_EQ(m["timestamp"], json::parse(R"({"sec":2,"nsec":1})"));
  EXPECT_EQ(m["pose"]["position"], json::parse(R"({"x":0.1,"y":-0.2,"z":1.5})"));
  EXPECT_EQ(m["pose"]["orientation"], json::parse(R"({"x":0.5,"y":-0.5,"z":0.5,"w":0.5})"));
  pose.valid(false);
  EXPECT_FALSE(pose_in_frame_json(pose)) << "a pose that is not valid is not drawn";
}

RobotState robot(bool broken, const std::string& job) {
  RobotState s;
  s.header(header(3'000'000'000ull, "r10/state"));
  s.robot("r10");
  s.radius(0.3);
  s.x(4.0);
  s.y(2.5);
  s.heading(std::numbers::pi / 2);
  s.speed(1.25);
  RobotJob j;
  j.id(job);
  s.job(j);
  s.broken(broken);
  s.fault(broken ? "motor" : "");
  return s;
}

TEST(FoxgloveMessages, ARobotIsASceneEntityWithADiscOfItsSizeFacingItsHeading) {
  const auto m = json::parse(*scene_update_json(robot(false, "j1")));
  EXPECT_EQ(off_schema("foxglove.SceneUpdate", m), "");
  ASSERT_EQ(m["entities"].size(), 1u);
  const auto& e = m["entities"][0];
  EXPECT_EQ(e["id"], "r10");
  EXPECT_EQ(e["frame_id"], "world");
  EXPECT_EQ(e["timestamp"], json::parse(R"({"sec":3,"nsec":0})"));
  ASSERT_EQ(e["cylinders"].size(), 1u);
  const auto& disc = e["cylinders"][0];
  EXPECT_DOUBLE_EQ(disc["pose"]["position"]["x"], 4.0);
  EXPECT_DOUBLE_EQ(disc["pose"]["position"]["y"], 2.5);
  EXPECT_DOUBLE_EQ(disc["size"]["x"], 0.6);
  EXPECT_DOUBLE_EQ(disc["size"]["y"], 0.6);
  const auto& q = e["arrows"][0]["pose"]["orientation"];  // heading pi/2 about +z
  EXPECT_NEAR(q["z"].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q["w"].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_EQ(e["texts"][0]["text"], "r10");
  EXPECT_GT(disc["color"]["g"].get<double>(), disc["color"]["r"].get<double>())
      << "working on a job: green";
}

TEST(FoxgloveMessages, ABrokenRobotIsRedAndSaysWhy) {
  const auto m = json::parse(*scene_update_json(robot(true, "")));
  EXPECT_EQ(off_schema("foxglove.SceneUpdate", m), "");
  const auto& e = m["entities"][0];
  const auto& c = e["cylinders"][0]["color"];
  EXPECT_GT(c["r"].get<double>(), c["g"].get<double>());
  EXPECT_GT(c["r"].get<double>(), c["b"].get<double>());
  EXPECT_NE(e["metadata"].dump().find(R"({"key":"fault","value":"motor"})"), std::string::npos)
      << e["metadata"].dump();
}

TEST(FoxgloveMessages, AFieldTheSchemaDoesNotDeclareIsFound) {
  auto m = json::parse(*scene_update_json(robot(false, "j1")));
  m["entities"][0]["cylinders"][0]["radius"] = 0.3;
  EXPECT_EQ(off_schema("foxglove.SceneUpdate", m),
            "$.entities[0].cylinders[0].radius is not declared");
  m = json::parse(*scene_update_json(robot(false, "j1")));
  m["entities"][0]["cubes"].push_back(m["entities"][0]["cylinders"][0]);
  EXPECT_EQ(off_schema("foxglove.SceneUpdate", m), "$.entities[0].cubes: more than 0 items");
}

}  // namespace
}  // namespace oscar::bridge
