#include "channel_directory.hpp"

#include <algorithm>

#include <gtest/gtest.h>

namespace oscar::bridge {
namespace {

using Writers = std::map<std::string, DdsParticipant::DiscoveredWriter>;

DdsParticipant::DiscoveredWriter writer(const std::string& type, int alive = 1) {
  DdsParticipant::DiscoveredWriter w;
  w.type = type;
  w.alive = alive;
  return w;
}

const std::map<std::string, std::string> kTexts{{"oscar::Bool", "bool idl"},
                                                {"oscar::GvImage", "image idl"}};
std::optional<std::string> kIdl(const std::string& type) {
  const auto it = kTexts.find(type);
  return it == kTexts.end() ? std::nullopt : std::optional(it->second);
}

TEST(ChannelDirectory, AdvertisesTopicsWithALiveWriterAndAnIdl) {
  ChannelDirectory d(kIdl);
  const auto change = d.update({{"oscar/cue/sig/out", writer("oscar::Bool")},
                                {"oscar/cue/cam/out", writer("oscar::GvImage")},
                                {"oscar/cue/old/out", writer("oscar::Bool", 0)},
                                {"rt/chatter", writer("oscar::Bool")},
                                {"oscar/cue/odd/out", writer("other::Type")}});
  ASSERT_EQ(change.added.size(), 2u);
  EXPECT_TRUE(change.removed.empty());
  EXPECT_EQ(change.unknown, std::vector<std::string>{"oscar/cue/odd/out"});
  const auto sig = d.id_of("oscar/cue/sig/out");
  ASSERT_TRUE(sig);
  ASSERT_NE(d.find(*sig), nullptr);
  EXPECT_EQ(d.find(*sig)->schema, "bool idl");
  EXPECT_EQ(d.find(*sig)->schema_name, "oscar::Bool");
  EXPECT_FALSE(d.id_of("oscar/cue/old/out"));
  EXPECT_TRUE(d.update({{"oscar/cue/odd/out", writer("other::Type")}}).unknown.empty())
      << "an unknown type is reported once";
}

TEST(ChannelDirectory, FollowsTopicsThatGoAndComeBack) {
  ChannelDirectory d(kIdl);
  d.update({{"oscar/cue/sig/out", writer("oscar::Bool")}});
  const auto id = *d.id_of("oscar/cue/sig/out");
  auto change = d.update({{"oscar/cue/sig/out", writer("oscar::Bool", 0)}});
  EXPECT_EQ(change.removed, std::vector<std::uint32_t>{id});
  EXPECT_EQ(d.find(id), nullptr);
  EXPECT_TRUE(d.channels().empty());
  change = d.update({{"oscar/cue/sig/out", writer("oscar::Bool")}});
  ASSERT_EQ(change.added.size(), 1u);
  EXPECT_EQ(change.added[0].id, id) << "same topic and type: the same channel id";
  change = d.update({{"oscar/cue/sig/out", writer("oscar::GvImage")}});
  EXPECT_EQ(change.removed, std::vector<std::uint32_t>{id});
  ASSERT_EQ(change.added.size(), 1u);
  EXPECT_NE(change.added[0].id, id) << "another type: another channel";
}

TEST(ChannelDirectory, AdvertisesATopicOnceItsModuleAnnouncedTheTypesIdl) {
  std::map<std::string, std::string> announced;
  ChannelDirectory d([&](const std::string& type) -> std::optional<std::string> {
    const auto it = announced.find(type);
    return it == announced.end() ? std::nullopt : std::optional(it->second);
  });
  const Writers writers{{"oscar/cue/arm/state", writer("acme::ArmState")}};
  auto change = d.update(writers);
  EXPECT_TRUE(change.added.empty());
  EXPECT_EQ(change.unknown, std::vector<std::string>{"oscar/cue/arm/state"});
  announced["acme::ArmState"] = "module acme { struct ArmState { double x; }; };";
  change = d.update(writers);
  ASSERT_EQ(change.added.size(), 1u);
  EXPECT_EQ(change.added[0].topic, "oscar/cue/arm/state");
  EXPECT_EQ(change.added[0].schema, announced["acme::ArmState"]);
  EXPECT_TRUE(change.unknown.empty());
}

// Two side channels for images only, as side_channels_for() makes them.
std::vector<ChannelInfo> image_side(const std::string& topic, const std::string& type) {
  if (type != "oscar::GvImage") return {};
  std::vector<ChannelInfo> out;
  for (const auto* schema : {"foxglove.RawImage", "foxglove.CompressedImage"}) {
    out.push_back({.id = 0,
                   .topic = "foxglove/" + topic + (out.empty() ? "" : "/compressed"),
                   .schema_name = schema,
                   .schema = "{}",
                   .encoding = "json",
                   .schema_encoding = "jsonschema",
                   .source = topic});
  }
  return out;
}

TEST(ChannelDirectory, SideChannelsComeAndGoWithTheirSource) {
  ChannelDirectory d(kIdl, image_side);
  auto change = d.update({{"oscar/cue/cam/out", writer("oscar::GvImage")},
                          {"oscar/cue/sig/out", writer("oscar::Bool")}});
  ASSERT_EQ(change.added.size(), 4u);
  const auto cam = *d.id_of("oscar/cue/cam/out");
  const auto sides = d.sides_of("oscar/cue/cam/out");
  ASSERT_EQ(sides.size(), 2u);
  EXPECT_NE(sides[0], cam);
  EXPECT_NE(sides[1], sides[0]);
  EXPECT_EQ(d.find(sides[0])->topic, "foxglove/oscar/cue/cam/out");
  EXPECT_EQ(d.find(sides[1])->topic, "foxglove/oscar/cue/cam/out/compressed");
  EXPECT_EQ(d.find(sides[0])->encoding, "json");
  EXPECT_TRUE(d.sides_of("oscar/cue/sig/out").empty());
  change = d.update({{"oscar/cue/sig/out", writer("oscar::Bool")}});
  std::sort(change.removed.begin(), change.removed.end());
  EXPECT_EQ(change.removed, (std::vector<std::uint32_t>{cam, sides[0], sides[1]}));
  EXPECT_TRUE(d.sides_of("oscar/cue/cam/out").empty());
  EXPECT_EQ(d.find(sides[0]), nullptr);
  change = d.update({{"oscar/cue/cam/out", writer("oscar::GvImage")},
                     {"oscar/cue/sig/out", writer("oscar::Bool")}});
  ASSERT_EQ(change.added.size(), 3u);
  EXPECT_EQ(d.sides_of("oscar/cue/cam/out"), sides) << "back with their source, under old ids";
}

}  // namespace
}  // namespace oscar::bridge
