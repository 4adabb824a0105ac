// A module of types OSCAR does not define (tests/own_types: acme::ArmState, acme::HoldRequest)
// in a booted system: it announces their IDL texts, and oscar echo, record, replay and config
// decode and encode them without its code (docs/kernels.md, "Types of your own").
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/mcap/reader.hpp"
#include "oscar/raw_cdr_type.hpp"
#include "oscar/raw_cue.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/type_texts.hpp"
#include "run_tool.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::Process;
using test::run_tool;
using ::testing::HasSubstr;

// The recording's channel of `topic`, or nullptr.
const mcap::Channel* channel_of(const mcap::FileInfo& info, const std::string& topic) {
  for (const auto& [id, channel] : info.channels) {
    if (channel.topic == topic) return &channel;
  }
  return nullptr;
}

// Waits until the recorder says it records `topic` (a recorder under a sanitizer on a loaded
// machine may take seconds to discover it).
void wait_until_recording(const Process& recorder, const std::string& topic) {
  ASSERT_TRUE(eventually(
      [&] { return recorder.output().find("recording " + topic) != std::string::npos; }, 60s))
      << recorder.output();
}

std::string arm_system(const std::string& tool) {
  return R"(
system: own_types
lease: 1s
plugins: [ )" +
         test::build_dir() + "/lib/oscar/test_plugins/liboscar_kernel_acme_arm.so" + R"( ]
modules:
  - name: arm
    kernels: [ { type: acme_arm, name: arm, params: { tool: )" +
         tool + R"( } } ]
    mode: { continuous: 50ms }
  - name: sig_source
    kernels: [ { type: bench_source, name: sig, params: { type: Bool } } ]
    mode: { continuous: 50ms }
)";
}

TEST(OwnTypes, AModuleAnnouncesTheIdlOfItsOwnTypesOnly) {
  BootedSystem system("own_types_announced", arm_system("gripper"));
  system.running();
  DdsParticipant participant(test::test_domain(), "own_types_test");
  const AnnouncedTypes announced(participant);
  const auto state = announced.wait_for("acme::ArmState", 10s);
  ASSERT_TRUE(state) << "the arm announced no IDL text for acme::ArmState";
  EXPECT_THAT(*state, HasSubstr("module acme"));
  EXPECT_THAT(*state, HasSubstr("struct ArmState"));
  EXPECT_THAT(*state, HasSubstr("struct CueHeader")) << "self-contained: OSCAR's header included";
  ASSERT_TRUE(announced.wait_for("acme::HoldRequest", 1s)) << "the command's request type";
  const auto all = announced.announced();
  EXPECT_EQ(all.size(), 2u) << "the bench source's Bool is OSCAR's own and not announced";
  EXPECT_FALSE(all.contains("oscar::Bool"));
  EXPECT_FALSE(idl_texts().contains("acme::ArmState"));
  ASSERT_EQ(system.shut_down(), 0) << system.boot_output();
}

TEST(OwnTypes, EchoRecordReplayAndConfigReadAndWriteThemWithoutTheModulesCode) {
  BootedSystem system("own_types_tools", arm_system("welder"));
  system.running();
  const auto domain = std::to_string(test::test_domain());

  const auto echoed = run_tool({"oscar-echo", "arm/state", "-d", domain, "-n", "2"});
  EXPECT_THAT(echoed, HasSubstr("oscar/cue/arm/state (acme::ArmState)"));
  EXPECT_THAT(echoed, HasSubstr("tool: \"welder\""));
  EXPECT_THAT(echoed, HasSubstr("grip: GRIP_OPEN"));
  EXPECT_THAT(echoed, HasSubstr("joints_rad"));

  const auto accepted =
      run_tool({"oscar-config", "arm", "command", "arm", "hold",
                "{seconds: 2.5, grip: GRIP_CLOSED}", "-d", domain, "--as", "coordinator"});
  EXPECT_THAT(accepted, HasSubstr("arm: arm accepted hold: holding closed for 2.5 s"));
  const auto refused =
      run_tool({"oscar-config", "arm", "command", "arm", "hold", "{seconds: 1, grip: GRIP_HALF}",
                "-d", domain, "--as", "coordinator"},
               2);
  EXPECT_THAT(refused, HasSubstr("the request is no acme::HoldRequest"));
  EXPECT_THAT(refused, HasSubstr("GRIP_HALF"));
  // The arm holds closed from here on: its next states say so.
  EXPECT_THAT(run_tool({"oscar-echo", "arm/state", "-d", domain, "-n", "1"}),
              HasSubstr("grip: GRIP_CLOSED"));

  const auto file = test::temp_path("own_types") + ".mcap";
  std::filesystem::remove(file);
  Process recorder({test::bin("oscar-record"), "-o", file, "--domain", domain, "--all"},
                   test::temp_path("own_types_record") + ".log");
  wait_until_recording(recorder, "oscar/cue/arm/state");
  std::this_thread::sleep_for(2500ms);
  recorder.stop();
  ASSERT_EQ(system.shut_down(), 0) << system.boot_output();

  mcap::Reader reader(file);
  const auto info = reader.info();
  const auto* arm = channel_of(info, "oscar/cue/arm/state");
  ASSERT_NE(arm, nullptr) << recorder.output();
  EXPECT_GE(info.statistics.channel_message_counts.at(arm->id), 10u);
  const auto schema = info.schemas.find(arm->schema_id);
  ASSERT_NE(schema, info.schemas.end()) << "recorded without a schema: " << recorder.output();
  EXPECT_EQ(schema->second.name, "acme::ArmState");
  EXPECT_EQ(schema->second.encoding, "omgidl");
  const std::string text(schema->second.data.begin(), schema->second.data.end());
  EXPECT_THAT(text, HasSubstr("struct ArmState"));
  EXPECT_THAT(text, HasSubstr("struct CueHeader"));

  // Replayed, the cues are decoded again: the replay announces the recorded texts.
  Process replay({test::bin("oscar-replay"), file, "--domain", domain, "--loop"},
                 test::temp_path("own_types_replay") + ".log");
  const auto replayed = run_tool({"oscar-echo", "arm/state", "-d", domain, "-n", "1"});
  EXPECT_THAT(replayed, HasSubstr("oscar/cue/arm/state (acme::ArmState)"));
  EXPECT_THAT(replayed, HasSubstr("tool: \"welder\"")) << replay.output();
  replay.stop();
}

// A writer no OSCAR module made (here: bytes under a type name nobody announced) has no IDL text
// anywhere: the recorder keeps its cues without a schema and says so, once.
TEST(OwnTypes, ATypeNobodyAnnouncedIsRecordedWithoutASchemaAndTheRecorderSaysSo) {
  DdsParticipant participant(test::test_domain(), "stray_writer");
  const std::string type = "acme::NobodyAnnounced";
  auto* writer = participant.publisher().create_datawriter(
      &participant.topic("oscar/cue/stray/out", new RawCdrType(type)), qos::stream_writer(16));
  ASSERT_NE(writer, nullptr);
  const auto file = test::temp_path("unannounced") + ".mcap";
  std::filesystem::remove(file);
  Process recorder({test::bin("oscar-record"), "-o", file, "--domain",
                    std::to_string(test::test_domain()), "--all"},
                   test::temp_path("unannounced_record") + ".log");
  wait_until_recording(recorder, "oscar/cue/stray/out");
  // Bool's bytes (a header first, as every cue) under the unknown name, every 50 ms for 2.5 s.
  for (std::uint64_t seq = 1; seq <= 50; ++seq) {
    Bool b;
    b.header().stamps({static_cast<unsigned long long>(seq)});
    b.header().source("stray/out");
    b.header().seq(seq);
    RawCue cue{.type = type, .cdr = cue_type_info<Bool>().serialize(&b), .cue_header = {}};
    ASSERT_TRUE(writer->write(&cue));
    std::this_thread::sleep_for(50ms);
  }
  recorder.stop();
  participant.publisher().delete_datawriter(writer);

  EXPECT_THAT(recorder.output(),
              HasSubstr("oscar/cue/stray/out (acme::NobodyAnnounced) is recorded without a schema: "
                        "OSCAR does not define its type and no module announced its IDL text"));
  mcap::Reader reader(file);
  const auto info = reader.info();
  const auto* stray = channel_of(info, "oscar/cue/stray/out");
  ASSERT_NE(stray, nullptr) << recorder.output();
  EXPECT_EQ(stray->schema_id, 0) << "no schema for a type nobody announced";
  EXPECT_EQ(stray->metadata.at("type"), type);
  EXPECT_GE(info.statistics.channel_message_counts.at(stray->id), 10u) << "its cues are kept";
}

}  // namespace
}  // namespace oscar
