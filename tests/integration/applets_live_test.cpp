// oscar applets run SCENARIO.yaml --live (docs/applets.md, "Live"): every shipped scenario runs
// offline and on a booted system with each applet in a process of its own; after every step the
// plan's holders (and who uses each service now) must be the same. And the live run leaves no
// process behind, also when it is interrupted.
#include <csignal>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "oscar/testing/eventually.hpp"
#include "process.hpp"
#include "source_tree.hpp"

namespace oscar {
namespace {

using ::testing::HasSubstr;

std::string scenario_file(const std::string& name) {
  return oscar::testing::source_path("coordinator/applets/scenarios/") + name + ".yaml";
}

// The JSON of the runner's output: the progress lines on stderr (which share the log) all come
// before it.
nlohmann::json steps_of(const std::string& output) {
  const auto start = output.starts_with("{") ? 0 : output.find("\n{");
  if (start == std::string::npos) {
    ADD_FAILURE() << "no JSON in the output:\n" << output;
    return nlohmann::json::array();
  }
  return nlohmann::json::parse(output.substr(start))["steps"];
}

struct Case {
  std::string scenario;
  std::string time_scale;  // see docs/applets.md: steps 100 ms apart with deadlines need room
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.scenario << " --time-scale " << c.time_scale;
}

class LiveScenario : public ::testing::TestWithParam<Case> {};

TEST_P(LiveScenario, HoldsAfterEveryStepWhatTheOfflineRunHolds) {
  const auto& c = GetParam();
  const auto file = scenario_file(c.scenario);
  test::Process offline({test::bin("oscar-applets"), "run", file, "--json"},
                        test::temp_path("live_offline_" + c.scenario) + ".out");
  ASSERT_EQ(offline.wait(std::chrono::seconds(60)), 0) << offline.output();
  test::Process live(
      {test::bin("oscar-applets"), "run", file, "--json", "--live", "--time-scale", c.time_scale},
      test::temp_path("live_" + c.scenario) + ".out");
  const auto code = live.wait(std::chrono::seconds(240));
  ASSERT_TRUE(code.has_value()) << "still running:\n" << live.output();
  EXPECT_EQ(*code, 0) << live.output();
  EXPECT_THAT(live.output(), HasSubstr("oscar applets run --live: booting"));

  const auto want = steps_of(offline.output());
  const auto got = steps_of(live.output());
  ASSERT_EQ(got.size(), want.size()) << live.output();
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i]["event"], want[i]["event"]);
    EXPECT_EQ(got[i]["holders"], want[i]["holders"])
        << "step " << i + 1 << " '" << want[i]["event"].get<std::string>() << "'\n"
        << live.output();
    EXPECT_EQ(got[i]["active"], want[i]["active"])
        << "step " << i + 1 << " '" << want[i]["event"].get<std::string>() << "'";
  }
  // Nothing of the temporary system is left: its processes have its file on their command line.
  EXPECT_THAT(test::processes_mentioning("/live_" + c.scenario + ".yaml"), ::testing::IsEmpty());
}

INSTANTIATE_TEST_SUITE_P(Shipped, LiveScenario,
                         ::testing::Values(Case{"real_world_5_3", "1"},
                                           Case{"appendix_counter", "1"}, Case{"negotiation", "1"},
                                           Case{"priorities_deadlines", "4"}),
                         [](const auto& p) { return p.param.scenario; });

TEST(LiveScenarioRun, CtrlCShutsTheSystemDownAndLeavesNothing) {
  test::Process live({test::bin("oscar-applets"), "run", scenario_file("negotiation"), "--live"},
                     test::temp_path("live_interrupted") + ".out");
  ASSERT_TRUE(eventually(
      [&] {
        return live.output().find("running the timeline") != std::string::npos ||
               live.wait(std::chrono::milliseconds(0)).has_value();
      },
      std::chrono::seconds(120)))
      << live.output();
  ASSERT_FALSE(live.wait(std::chrono::milliseconds(0)).has_value()) << live.output();
  kill(live.pid(), SIGINT);
  const auto code = live.wait(std::chrono::seconds(60));
  ASSERT_TRUE(code.has_value()) << live.output();
  EXPECT_EQ(*code, 2) << live.output();
  EXPECT_THAT(live.output(), HasSubstr("interrupted"));
  EXPECT_THAT(test::processes_mentioning("/live_negotiation.yaml"), ::testing::IsEmpty());
}

}  // namespace
}  // namespace oscar
