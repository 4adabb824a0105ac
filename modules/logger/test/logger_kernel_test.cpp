#include "logger_kernel.hpp"

#include <unistd.h>

#include <filesystem>
#include <map>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/cue_type_info.hpp>
#include <oscar/cue_types.hpp>
#include <oscar/harness.hpp>
#include <oscar/idl_texts.hpp>
#include <oscar/mcap/reader.hpp>
#include <oscar/perception_types.hpp>
#include <oscar/testing/conformance.hpp>

namespace oscar::modules {
namespace {
using testing::HasSubstr;
using testing::ThrowsMessage;

std::string temp(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("logger_" + name + "_" + std::to_string(getpid()) + ".mcap"))
      .string();
}

OSCAR_KERNEL_CONFORMANCE_TEST(LoggerTwoInputs, "logger",
                              "{file: /tmp/oscar_logger_conformance.mcap, inputs: 'a, b', "
                              "compression: lz4}")

TEST(Logger, WritesEveryCueOfEveryInputAsMcapWithItsHeaderTimes) {
  const auto file = temp("two");
  {
    KernelHarness h("logger", YAML::Load("{file: " + file + ", inputs: 'flag, lines'}"), "log");
    for (int i = 1; i <= 3; ++i) {
      Bool b;
      b.header().source("sig/out");
      b.header().seq(i);
      append_stamp(b.header(), 100 * i);
      b.value(i % 2 == 1);
      h.feed("flag", b);
    }
    LineSeg3DSeq l;
    l.header().source("cam/lines");
    l.header().seq(7);
    append_stamp(l.header(), 555);
    l.lines().resize(4);
    h.feed("lines", l);
    h.step();
    h.step();  // nothing new: nothing written twice
  }            // the kernel is destroyed: the file is finished
  mcap::Reader reader(file);
  std::vector<std::string> seen;
  std::uint64_t last_log_time = 0;
  reader.read_messages([&](const mcap::Channel& c, const mcap::MessageView& m) {
    const std::vector<std::uint8_t> bytes(m.data.begin(), m.data.end());
    if (c.topic == "oscar/cue/sig/out") {
      EXPECT_EQ(c.metadata.at("type"), "oscar::Bool");
      EXPECT_EQ(c.metadata.at("kernel"), "sig");
      EXPECT_EQ(c.metadata.at("channel"), "out");
      const auto b = std::static_pointer_cast<Bool>(cue_type_info<Bool>().deserialize(bytes));
      EXPECT_EQ(m.sequence, b->header().seq());
      EXPECT_EQ(m.publish_time, 100u * b->header().seq());
      EXPECT_EQ(b->value(), b->header().seq() % 2 == 1);
    } else {
      EXPECT_EQ(c.topic, "oscar/cue/cam/lines");
      EXPECT_EQ(c.message_encoding, "cdr");
      const auto l2 =
          std::static_pointer_cast<LineSeg3DSeq>(cue_type_info<LineSeg3DSeq>().deserialize(bytes));
      EXPECT_EQ(l2->lines().size(), 4u);
      EXPECT_EQ(m.publish_time, 555u);
    }
    seen.push_back(c.topic + "#" + std::to_string(m.sequence));
    EXPECT_GE(m.log_time, last_log_time) << "the file is in the order the cues arrived";
    last_log_time = m.log_time;
  });
  EXPECT_THAT(seen, testing::UnorderedElementsAre("oscar/cue/sig/out#1", "oscar/cue/sig/out#2",
                                                  "oscar/cue/sig/out#3", "oscar/cue/cam/lines#7"));
  const auto schemas = reader.info().schemas;
  ASSERT_EQ(schemas.size(), 2u);
  for (const auto& [id, s] : schemas) {
    (void)id;
    EXPECT_EQ(s.encoding, "omgidl");
    EXPECT_THAT(std::string(s.data.begin(), s.data.end()), HasSubstr("struct CueHeader"));
  }
  std::filesystem::remove(file);
}

TEST(Logger, CreatesNoFileBeforeTheFirstCue) {
  const auto file = temp("none");
  {
    KernelHarness h("logger", YAML::Load("{file: " + file + ", inputs: 'x'}"));
    h.step();
  }
  EXPECT_FALSE(std::filesystem::exists(file));
}

// The landmark application's own cues: types the logger does not name, taken from the wiring.
TEST(Logger, RecordsCuesOfAnyTypeWithTheIdlTextOfTheirType) {
  const auto file = temp("landmarks");
  TagDetections tags;
  tags.header().source("mark_a/tags");
  tags.header().seq(3);
  append_stamp(tags.header(), 700);
  tags.camera_id("cam_a");
  tags.detections().resize(1);
  tags.detections()[0].id(5);
  tags.detections()[0].corners()[2] = 12.5;
  LandmarkPose pose;
  pose.header().source("pose/pose");
  pose.header().seq(9);
  pose.header().stamps({700, 800, 900});
  pose.valid(true);
  pose.estimates(2);
  {
    KernelHarness h("logger", YAML::Load("{file: " + file + "}"), "log",
                    {{"tags", InputOverrides{}}, {"pose", InputOverrides{}}});
    h.feed("tags", tags);
    h.feed("pose", pose);
    h.step();
  }
  mcap::Reader reader(file);
  std::map<std::string, std::string> type_of;
  reader.read_messages([&](const mcap::Channel& c, const mcap::MessageView& m) {
    const std::vector<std::uint8_t> bytes(m.data.begin(), m.data.end());
    type_of[c.topic] = c.metadata.at("type");
    if (c.topic == "oscar/cue/mark_a/tags") {
      const auto t = std::static_pointer_cast<TagDetections>(
          cue_type_info<TagDetections>().deserialize(bytes));
      EXPECT_EQ(*t, tags) << "the bytes are the cue's serialization";
      EXPECT_EQ(m.sequence, 3u);
      EXPECT_EQ(m.publish_time, 700u);
    } else {
      ASSERT_EQ(c.topic, "oscar/cue/pose/pose");
      const auto p =
          std::static_pointer_cast<LandmarkPose>(cue_type_info<LandmarkPose>().deserialize(bytes));
      EXPECT_EQ(*p, pose);
      EXPECT_EQ(m.publish_time, 700u) << "the first stamp: when the data was generated";
    }
  });
  EXPECT_EQ(type_of,
            (std::map<std::string, std::string>{{"oscar/cue/mark_a/tags", "oscar::TagDetections"},
                                                {"oscar/cue/pose/pose", "oscar::LandmarkPose"}}));
  std::set<std::string> schemas;
  for (const auto& [id, s] : reader.info().schemas) {
    (void)id;
    EXPECT_EQ(s.encoding, "omgidl");
    EXPECT_EQ(std::string(s.data.begin(), s.data.end()), idl_texts().at(s.name)) << s.name;
    schemas.insert(s.name);
  }
  EXPECT_THAT(schemas, testing::ElementsAre("oscar::LandmarkPose", "oscar::TagDetections"));
  std::filesystem::remove(file);
}

TEST(Logger, RejectsBadInputDeclarations) {
  EXPECT_THAT(
      [] { KernelHarness h("logger", YAML::Load("{file: /tmp/x.mcap, inputs: 'flag: Bool'}")); },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("logger: parameter 'inputs': 'flag: Bool' names a type; give the input name "
                    "only ('flag'): the logger takes each producer's type")));
  EXPECT_THAT([] { KernelHarness h("logger", YAML::Load("{file: /tmp/x.mcap, inputs: 'a b'}")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr(
                  "logger: parameter 'inputs': 'a b' is not an input name (e.g. 'cam, flag')")));
  EXPECT_THAT([] { KernelHarness h("logger", YAML::Load("{file: /tmp/x.mcap, inputs: 'a,a'}")); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("logger: parameter 'inputs': input 'a' is named twice")));
  EXPECT_THAT([] { KernelHarness h("logger", YAML::Load("{file: /tmp/x.mcap}")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr(
                  "logger: nothing to record: wire inputs in the kernel's inputs: (e.g. inputs: "
                  "{ tags: mark_a/tags }) or name them in parameter 'inputs'")));
  EXPECT_THAT([] { KernelHarness h("logger", YAML::Load("{inputs: 'a'}")); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("logger: parameter 'file' must name the MCAP file to write")));
}

TEST(Logger, AnInputOfAnyTypeRefusesPullTransfer) {
  EXPECT_THAT(
      [] {
        KernelHarness h(
            "logger", YAML::Load("{file: /tmp/x.mcap}"), "log",
            {{"a", InputOverrides{.depth = std::nullopt, .transfer = Transfer::kPull}}});
      },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("kernel 'log' (logger): input 'a' takes cues of any type, which arrive by "
                    "push only, not pull")));
}

TEST(Logger, AnUnwritableFileIsAClearErrorOnTheFirstCue) {
  KernelHarness h("logger", YAML::Load("{file: /proc/nonexistent/x.mcap, inputs: 'a'}"));
  h.feed("a", Bool{});
  EXPECT_ANY_THROW(h.step());
}

}  // namespace
}  // namespace oscar::modules
