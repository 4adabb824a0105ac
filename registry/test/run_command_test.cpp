#include "oscar/registry/run_command.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar {
namespace {

using namespace std::chrono_literals;

TEST(RunCommand, GivesItsInputAndKeepsItsOutputAndExitCode) {
  const auto r = run_command({"sh", "-c", "cat; echo oops >&2; exit 3"}, 10s, "system: a\n");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.output, "system: a\noops\n");
}

TEST(RunCommand, InputLargerThanAPipeReachesAChildThatAnswersFirst) {
  const std::string input(1 << 20, 'x');
  const auto r = run_command({"sh", "-c", "echo first; wc -c"}, 20s, input);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output, "first\n1048576\n");
}

TEST(RunCommand, SurvivesAChildThatReadsNoInput) {
  const auto r = run_command({"true"}, 10s, std::string(1 << 20, 'x'));
  EXPECT_EQ(r.exit_code, 0);
}

TEST(RunCommand, KillsACommandThatOutlivesItsTimeout) {
  const auto r = run_command({"sleep", "10"}, 200ms);
  EXPECT_EQ(r.exit_code, -1);
}

TEST(RunCommand, SaysWhenTheProgramCannotBeStarted) {
  const auto r = run_command({"/nonexistent/oscar-monitor"}, 10s);
  EXPECT_EQ(r.exit_code, 127);
  EXPECT_THAT(r.output, ::testing::HasSubstr("/nonexistent/oscar-monitor: cannot be started"));
}

}  // namespace
}  // namespace oscar
