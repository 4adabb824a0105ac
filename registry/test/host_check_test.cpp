#include "oscar/registry/host_check.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/cue_types.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/registry/run_command.hpp"

namespace oscar {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

HostSpec robot() {
  HostSpec h;
  h.name = "robot";
  h.kind = HostSpec::Kind::kSsh;
  h.ssh = "oscar@robot";
  h.address = "10.77.0.2";
  return h;
}

std::string explain(int exit_code, const std::string& output) {
  return explain_host_check(robot(), "/opt/oscar/bin/oscar-monitor", exit_code, output)
      .value_or("ready");
}

TEST(HostCheck, AHostThatAnswersWithTheSameVersionAndNoProblemIsReady) {
  EXPECT_EQ(explain(0, check_banner() + "\n"), "ready");
  EXPECT_EQ(explain(0, "Warning: Permanently added '[10.77.0.2]:22' (ED25519)\n" + check_banner()),
            "ready");
}

TEST(HostCheck, SshFailuresNameTheHostAndTheCause) {
  EXPECT_EQ(explain(255, "ssh: connect to host robot port 22: Connection refused\n"),
            "host 'robot' (oscar@robot): unreachable (ssh: connect to host robot port 22: "
            "Connection refused)");
  EXPECT_THAT(explain(255, "oscar@robot: Permission denied (publickey).\n"),
              HasSubstr("host 'robot' (oscar@robot): authentication refused (oscar@robot: "
                        "Permission denied (publickey).)"));
  EXPECT_THAT(explain(255, "Host key verification failed.\n"),
              HasSubstr("host 'robot' (oscar@robot): its host key is not trusted"));
  EXPECT_EQ(explain(-1, ""), "host 'robot' (oscar@robot): unreachable: no answer in time");
}

TEST(HostCheck, AMissingMonitorOrAnotherVersionIsNamed) {
  EXPECT_THAT(
      explain(126, "bash: line 1: /opt/oscar/bin/oscar-monitor: Permission denied\n"),
      HasSubstr("host 'robot' (oscar@robot): cannot run /opt/oscar/bin/oscar-monitor there, "
                "it is not executable (bash: line 1: /opt/oscar/bin/oscar-monitor: "
                "Permission denied)"));
  EXPECT_THAT(explain(127, "sh: 1: /opt/oscar/bin/oscar-monitor: not found\n"),
              HasSubstr("host 'robot' (oscar@robot): missing program "
                        "/opt/oscar/bin/oscar-monitor (install this OSCAR build"));
  EXPECT_EQ(explain(0, "oscar-monitor 0.0.9\n"),
            fmt::format("host 'robot' (oscar@robot): version mismatch: oscar-monitor 0.0.9 there, "
                        "{} here; install OSCAR {} there",
                        check_banner(), oscar_version()));
  EXPECT_THAT(explain(2, "The following argument was not expected: --check\n"),
              HasSubstr("version mismatch: its oscar-monitor knows no --check"));
}

TEST(HostCheck, TheHostsOwnProblemsAreReportedOnOneLine) {
  EXPECT_EQ(explain(2, check_banner() + "\nmodule 'a': x\nmodule 'b': y\n"),
            "host 'robot' (oscar@robot): module 'a': x; module 'b': y");
}

TEST(HostCheck, FingerprintsDifferWithTheContent) {
  EXPECT_EQ(content_fingerprint("a"), content_fingerprint("a"));
  EXPECT_NE(content_fingerprint("system: a"), content_fingerprint("system: b"));
  EXPECT_EQ(content_fingerprint("").size(), 16u);
}

// Every program "installed": the programs of this build are not beside the test.
std::string installed(const std::string&) { return "/bin/true"; }

class ThisHost : public testing::Test {
 protected:
  void SetUp() override {
    register_standard_cue_types();
    dir_ = std::filesystem::temp_directory_path() / fmt::format("host_check_{}", getpid());
    std::filesystem::create_directories(dir_);
    file_ = (dir_ / "system.yaml").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::vector<std::string> check(const std::string& yaml) {
    std::ofstream(file_) << yaml;
    return check_this_host(file_, "robot", content_fingerprint(yaml), plugin_search_path(),
                           installed);
  }

  std::filesystem::path dir_;
  std::string file_;
};

constexpr const char* kSystem = R"(
hosts: { here: { local: true }, robot: { ssh: oscar@robot, address: 10.77.0.2 } }
modules:
  - { name: a, host: robot, kernels: [ { type: relay, params: { type: Bool } } ] }
  - { name: b, host: here, kernels: [ { type: no_such_kernel } ] }
)";

TEST_F(ThisHost, IsReadyWhenItsModulesLoadAndOtherHostsModulesAreNotItsConcern) {
  EXPECT_THAT(check(kSystem), ElementsAre());
}

TEST_F(ThisHost, NamesAMissingPluginOfOneOfItsModules) {
  std::string yaml = kSystem;
  yaml.replace(yaml.find("type: relay"), 11, "type: lidar_fusion");
  const auto problems = check(yaml);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_THAT(problems[0], HasSubstr("module 'a': "));
  EXPECT_THAT(problems[0], HasSubstr("lidar_fusion"));
}

TEST_F(ThisHost, NamesAMissingProgram) {
  std::ofstream(file_) << kSystem;
  const auto problems =
      check_this_host(file_, "robot", content_fingerprint(kSystem), plugin_search_path(),
                      [](const std::string& program) { return "/nowhere/" + program; });
  EXPECT_THAT(problems, ElementsAre("module 'a': missing program /nowhere/oscar-run (install this "
                                    "OSCAR build at the same path)"));
}

TEST_F(ThisHost, NamesAMissingOrDifferentSystemFile) {
  std::ofstream(file_) << kSystem;
  EXPECT_THAT(check_this_host(file_, "robot", content_fingerprint("other"), plugin_search_path(),
                              installed),
              ElementsAre(fmt::format(
                  "the system file {} differs from boot's (copy boot's to the same path)", file_)));
  std::filesystem::remove(file_);
  EXPECT_THAT(check_this_host(file_, "robot", content_fingerprint(kSystem), plugin_search_path(),
                              installed),
              ElementsAre(fmt::format("the system file {} is not there (copy it to the same path)",
                                      file_)));
}

TEST_F(ThisHost, ResolvesThePluginFoldersRelativeToTheSystemFile) {
  std::string yaml = kSystem;
  yaml = "plugins: [my_plugins]\n" + yaml;
  const auto problems = check(yaml);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_THAT(problems[0], HasSubstr("my_plugins"));
  std::filesystem::create_directories(dir_ / "my_plugins");
  EXPECT_THAT(check(yaml), ElementsAre());
}

TEST_F(ThisHost, CopyingTheSystemFileCreatesItsFolderAndReplacesAnOldCopy) {
  HostSpec here;  // the same command as over ssh, run here
  const auto file = (dir_ / "new folder" / "system.yaml").string();
  for (const std::string content : {"system: first\n", "system: second\n"}) {
    const auto put =
        run_command(copy_system_file_command(here, file), std::chrono::seconds(10), content);
    EXPECT_EQ(put.exit_code, 0) << put.output;
    EXPECT_EQ(read_text_file(file), content);
  }
  EXPECT_FALSE(std::filesystem::exists(file + ".oscar-copy"));
}

}  // namespace
}  // namespace oscar
