#include "logger_kernel.hpp"

#include <unistd.h>

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/cue_type_info.hpp>
#include <oscar/cue_types.hpp>
#include <oscar/harness.hpp>
#include <oscar/mcap/reader.hpp>
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

OSCAR_KERNEL_CONFORMANCE_TEST(LoggerTwoTypes, "logger",
                              "{file: /tmp/oscar_logger_conformance.mcap, inputs: 'a:Bool, "
                              "b:GvImage', compression: lz4}")

TEST(Logger, WritesEveryCueOfEveryInputAsMcapWithItsHeaderTimes) {
  const auto file = temp("two");
  {
    KernelHarness h("logger",
                    YAML::Load("{file: " + file + ", inputs: 'flag: Bool, lines: LineSeg3DSeq'}"),
                    "log");
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
    KernelHarness h("logger", YAML::Load("{file: " + file + ", inputs: 'x:Bool'}"));
    h.step();
  }
  EXPECT_FALSE(std::filesystem::exists(file));
}

TEST(Logger, RejectsBadInputDeclarations) {
  EXPECT_THAT([] { KernelHarness h("logger", YAML::Load("{file: /tmp/x.mcap, inputs: 'cam'}")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr(
                  "logger: parameter 'inputs': 'cam' is not 'name:Type' (e.g. 'cam:GvImage, "
                  "flag:Bool')")));
  EXPECT_THAT(
      [] { KernelHarness h("logger", YAML::Load("{file: /tmp/x.mcap, inputs: 'a:Bool,a:Bool'}")); },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("logger: parameter 'inputs': input 'a' is declared twice")));
  EXPECT_THAT([] { KernelHarness h("logger", YAML::Load("{file: /tmp/x.mcap, inputs: 'a:Img'}")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr(
                  "cue type 'Img' is not a standard type (Bool, LineSeg3DSeq, GvImage)")));
  EXPECT_THAT([] { KernelHarness h("logger", YAML::Load("{inputs: 'a:Bool'}")); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("logger: parameter 'file' must name the MCAP file to write")));
}

TEST(Logger, AnUnwritableFileIsAClearErrorOnTheFirstCue) {
  KernelHarness h("logger", YAML::Load("{file: /proc/nonexistent/x.mcap, inputs: 'a:Bool'}"));
  h.feed("a", Bool{});
  EXPECT_ANY_THROW(h.step());
}

}  // namespace
}  // namespace oscar::modules
