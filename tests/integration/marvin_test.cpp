// Seed 004 §4.2's MARVIN mission as a live system (config/marvin-phases.yaml): the applet
// `mission` goes from phase explore to identify when the door search sees a sign and back after
// reading it; the plan runs exactly the modules of the phase, and granting HalfFrames switches
// the framegrabber to half frames (its idle switches it back to quarter). While it explores, the
// door search's resource wish (a closer look at a sign) gets HalfFrames, until the mission's
// identify phase takes it.
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/testing/eventually.hpp"
#include "plan_watch.hpp"
#include "source_tree.hpp"

namespace oscar {
namespace {

using ::testing::HasSubstr;

// The shipped system file, ending after `doors` doors, exploring for at least 4 s and reading each
// sign for 3 s: long enough for the registry's state to show the phase when the machine is loaded
// (with 1.5 s of exploring, the mission once moved on under the address sanitizer before its
// modules had answered the coordinator's commands).
std::string marvin_system(int doors) {
  std::ifstream in(oscar::testing::source_path("config/marvin-phases.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  auto yaml = text.str();
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = yaml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) yaml.replace(at, from.size(), to);
  };
  replace("doors: 0", "doors: " + std::to_string(doors));
  replace("explore_min_ms: 1500", "explore_min_ms: 4000");
  replace("read_ms: 1000", "read_ms: 3000");
  return yaml;
}

class Mission {
 public:
  explicit Mission(int doors) : sys("marvin", marvin_system(doors)), plans_(sys.participant()) {}

  // Waits until the plan gives `mission` exactly `held` of the mission's services.
  ::testing::AssertionResult holds(const std::set<std::string>& held) {
    static const std::set<std::string> kServices{"WallFollowing", "DoorSearch", "DoorLocalisation",
                                                 "HalfFrames"};
    return shown("the mission's services for its phase", [&](const AppletPlan& p) {
      for (const auto& s : p.services()) {
        if (!kServices.contains(s.name())) continue;
        const bool mission = s.holders() == std::vector<std::string>{"mission"};
        if (mission != held.contains(s.name())) return false;
      }
      return true;
    });
  }

  // Waits until the plan gives `service` to `holders`.
  ::testing::AssertionResult held_by(const std::string& service,
                                     const std::vector<std::string>& holders) {
    return shown(service + "'s holders", [&](const AppletPlan& p) {
      return test::PlanWatch::holders(p, service) == holders;
    });
  }

  // Waits until each module's kernel (named like the module) is in its mode ("deactivated" or
  // not), and cam's frame mode is `frame_mode`.
  void modules(const std::map<std::string, bool>& active, const std::string& frame_mode) {
    sys.wait_for([&](const SystemState& st) {
      for (const auto& [module, on] : active) {
        const auto* m = test::entry(st, module);
        const auto* k = m ? test::kernel_state(*m, module) : nullptr;
        if (!k || (k->mode() != "deactivated") != on) return false;
      }
      const auto* cam = test::entry(st, "cam");
      const auto* k = cam ? test::kernel_state(*cam, "cam") : nullptr;
      return k && k->params().find("frame_mode: " + frame_mode) != std::string::npos;
    });
  }

  test::BootedSystem sys;

 private:
  ::testing::AssertionResult shown(const std::string& what,
                                   const std::function<bool(const AppletPlan&)>& shows) {
    if (plans_.wait(shows)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "the plan never showed " << what
                                         << "; last: " << plans_.last_json() << "\nboot output:\n"
                                         << sys.boot_output();
  }

  test::PlanWatch plans_;
};

TEST(MarvinMission, EachPhaseRunsItsModulesAndSwitchesTheFramegrabbersFrameMode) {
  Mission m(2);
  m.sys.running();
  // Phase explore: wall following and door search; the door search sees a sign and wishes a
  // closer look, which the plan grants it: half frames.
  ASSERT_TRUE(m.holds({"WallFollowing", "DoorSearch"}));
  ASSERT_TRUE(m.held_by("HalfFrames", {"door_search/door_search"}));
  m.modules({{"wall_follow", true}, {"cam", true}, {"door_search", true}, {"door_locate", false}},
            "half");
  // Phase identify: the door search saw a sign; the door is localised on half frames, which the
  // mission now holds itself (its priority is higher than the wish's).
  ASSERT_TRUE(m.holds({"DoorLocalisation", "HalfFrames"}));
  m.modules({{"wall_follow", false}, {"cam", true}, {"door_search", false}, {"door_locate", true}},
            "half");
  // The next door: explore again.
  ASSERT_TRUE(m.holds({"WallFollowing", "DoorSearch"}));
  m.modules({{"wall_follow", true}, {"door_search", true}, {"door_locate", false}}, "half");
  // After the second door the mission is done: nothing held, every module deactivated. (A
  // phase change releases one bundle and then requests the next: a plan between the two may show
  // nothing held, so the end is taken from the mission's word.)
  ASSERT_TRUE(m.holds({"DoorLocalisation", "HalfFrames"}));
  ASSERT_TRUE(eventually(
      [&] {
        return m.sys.boot_output().find(
                   "applet mission: phase identify -> done (all doors "
                   "identified)") != std::string::npos;
      },
      std::chrono::seconds(30)))
      << m.sys.boot_output();
  ASSERT_TRUE(m.holds({}));
  m.modules(
      {{"wall_follow", false}, {"cam", false}, {"door_search", false}, {"door_locate", false}},
      "quarter");
  const auto log = m.sys.boot_output();
  EXPECT_THAT(log, HasSubstr("applet mission: phase explore -> identify (door sign seen)"));
  EXPECT_THAT(log, HasSubstr("applet mission: door 2 identified"));
  EXPECT_THAT(log, HasSubstr("coordinator: cam/cam: set frame_mode=half"));
  EXPECT_THAT(log, HasSubstr("coordinator: kernel door_search/door_search asks for its wish "
                             "closer_look"));
}

}  // namespace
}  // namespace oscar
