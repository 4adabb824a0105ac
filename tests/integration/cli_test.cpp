// Every oscar tool reads its command line the same way: --help prints the usage and exits 0, a
// usage error names what is wrong and exits 2 (docs: "2 = bad input or a usage error").
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "process.hpp"  // tests/common
#include "source_tree.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using ::testing::HasSubstr;

const char* const kTools[] = {"oscar-applet",     "oscar-applets",     "oscar-boot",
                              "oscar-config",     "oscar-coordinator", "oscar-discovery-server",
                              "oscar-echo",       "oscar-graph",       "oscar-hz",
                              "oscar-info",       "oscar-log",         "oscar-monitor",
                              "oscar-new-module", "oscar-ps",          "oscar-record",
                              "oscar-registry",   "oscar-replay",      "oscar-restart",
                              "oscar-run",        "oscar-swarm",       "oscar-shutdown",
                              "oscar-topics",     "oscar-bridge"};

struct Run {
  int exit_code;
  std::string output;
};

Run run(const std::string& tool, std::vector<std::string> args) {
  const auto log = (std::filesystem::temp_directory_path() /
                    (tool + "_cli_" + std::to_string(getpid()) + ".log"))
                       .string();
  args.insert(args.begin(), test::bin(tool));
  test::Process p(args, log);
  const auto rc = p.wait(30s);
  Run r{rc.value_or(-1), p.output()};
  std::filesystem::remove(log);
  return r;
}

TEST(CommandLine, EveryToolExitsWith2OnAUsageErrorAndSaysWhatIsWrong) {
  for (const auto* tool : kTools) {
    const auto r = run(tool, {"--no-such-option"});
    EXPECT_EQ(r.exit_code, 2) << tool << ":\n" << r.output;
    // CLI11 names the first thing wrong: a missing argument, or else the unknown option.
    EXPECT_THAT(r.output, ::testing::ContainsRegex("(is required|--no-such-option)")) << tool;
    EXPECT_THAT(r.output, HasSubstr("Run with --help for more information")) << tool;
  }
}

TEST(CommandLine, EveryToolPrintsItsUsageAndExits0OnHelp) {
  for (const auto* tool : kTools) {
    const auto r = run(tool, {"--help"});
    EXPECT_EQ(r.exit_code, 0) << tool << ":\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr("--help")) << tool;
  }
}

TEST(CommandLine, TheDispatcherPassesTheToolsExitCodeOn) {
  EXPECT_EQ(run("oscar", {"ps", "--no-such-option"}).exit_code, 2);
}

TEST(CommandLine, AppletsRunDrawsWithSvgAsWithDot) {
  const auto svg =
      (std::filesystem::temp_directory_path() / ("applets_" + std::to_string(getpid()) + ".svg"))
          .string();
  const auto r =
      run("oscar-applets",
          {"run", oscar::testing::source_path("coordinator/applets/scenarios/real_world_5_3.yaml"),
           "--svg", svg});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(svg + ".dot")) << r.output;
  std::filesystem::remove(svg);
  std::filesystem::remove(svg + ".dot");
}

TEST(CommandLine, AppletsPsSaysSoWhenNoCoordinatorPublishesAPlan) {
  const auto r =
      run("oscar-applets", {"ps", "-d", std::to_string(test::test_domain()), "--timeout", "0.5"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("no coordinator published its plan on domain"));
}

TEST(CommandLine, TheCoordinatorRefusesASystemFileWithoutACoordinatorSection) {
  const auto r = run("oscar-coordinator", {oscar::testing::source_path("config/demo-local.yaml")});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("demo-local.yaml: no coordinator: section"));
}

}  // namespace
}  // namespace oscar
