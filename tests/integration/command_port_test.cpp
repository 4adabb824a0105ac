// Command ports across processes (docs/kernels.md, "Command ports"): a module process takes a
// kernel's command from ConfigClient and from `oscar config ... command`, and answers.
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/command_types.hpp"
#include "oscar/config_client.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/testing/eventually.hpp"
#include "process.hpp"  // tests/common
#include "source_tree.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::Process;
using ::testing::HasSubstr;

struct Run {
  int exit_code;
  std::string output;
};

// `oscar config MODULE command ...` as the coordinator.
Run config(const std::string& module, std::vector<std::string> args) {
  const auto log = test::temp_path("oscar_config_command.log");
  std::vector<std::string> argv{test::bin("oscar-config"), module, "command"};
  argv.insert(argv.end(), args.begin(), args.end());
  for (const auto& a : {"--as", "coordinator", "--domain"}) argv.emplace_back(a);
  argv.push_back(std::to_string(test::test_domain()));
  Process p(argv, log);
  const auto rc = p.wait(30s);
  return {rc.value_or(-1), p.output()};
}

Bool flag(bool value) {
  Bool b;
  b.value(value);
  return b;
}

TEST(CommandPortsAcrossProcesses, AModuleProcessAnswersOnItsProcessingThreadBetweenCycles) {
  auto arm = test::run_module(
      "arm",
      {"--plugin",
       oscar::testing::build_path("lib/oscar/test_plugins/liboscar_kernel_test_commanded.so"), "-k",
       "test_commanded:arm", "-m", "continuous:2ms"});
  DdsParticipant participant(test::test_domain(), "test:coordinator");
  ConfigClient client(participant, "coordinator");
  ASSERT_TRUE(eventually([&] { return client.module_state("arm", 5s).kernels()[0].cycles() > 3; }))
      << arm->output();
  for (int i = 0; i < 20; ++i) {
    const auto reply = client.command("arm", "arm", "hold", flag(true));
    ASSERT_TRUE(reply.ok()) << reply.error();
    EXPECT_TRUE(reply.answered());
    EXPECT_EQ(reply.answer(), "held; on the processing thread: yes; during process(): no");
  }
  auto reply = client.command("arm", "arm", "hold", flag(false));
  EXPECT_FALSE(reply.ok());
  EXPECT_TRUE(reply.answered());
  EXPECT_EQ(reply.error(), "command 'hold' refused by kernel 'arm': told not to hold");
  reply = client.command("arm", "arm", "jump", flag(true));
  EXPECT_FALSE(reply.answered());
  EXPECT_THAT(reply.error(), HasSubstr("has no command 'jump'; its commands: hold (oscar::Bool), "
                                       "mode (oscar::SetFrameMode)"));
  const auto state = client.module_state("arm");
  ASSERT_EQ(state.kernels()[0].commands().size(), 2u);
  EXPECT_EQ(state.kernels()[0].commands()[1].type(), "oscar::SetFrameMode");
}

TEST(CommandPortsAcrossProcesses, OscarConfigSendsTheFramegrabbersFrameModeFromYaml) {
  auto cams = test::run_module("cams", {"-k", "framegrabber:cam", "-m", "continuous:50ms"});
  auto r = config("cams", {"cam", "frame_mode", "{mode: half}"});
  ASSERT_EQ(r.exit_code, 0) << r.output << cams->output();
  EXPECT_THAT(r.output, HasSubstr("cams: cam accepted frame_mode: frame mode full -> half"));
  r = config("cams", {"cam", "frame_mode", "mode: quarter"});
  EXPECT_THAT(r.output, HasSubstr("frame mode half -> quarter"));

  r = config("cams", {"cam", "frame_mode", "{mode: eighth}"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("cams: command 'frame_mode' refused by kernel 'cam': frame "
                                  "mode 'eighth' is not full, half or quarter"));
  r = config("cams", {"cam", "frame_mode", "{mod: half}"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("the request is no oscar::SetFrameMode: oscar::SetFrameMode has "
                                  "no member 'mod' (members: mode)"));
  r = config("cams", {"cam", "frame_mode", "{mode: [half"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("the request is no YAML"));
  r = config("cams", {"cam", "zoom", "{}"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("kernel 'cam' (framegrabber) has no command 'zoom'; its "
                                  "commands: frame_mode (oscar::SetFrameMode)"));
}

}  // namespace
}  // namespace oscar
