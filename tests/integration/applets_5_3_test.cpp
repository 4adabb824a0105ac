// Seed 000 §5.3 as a live system (config/applets-5-3.yaml): the seven steps of the real-world
// scenario are sent to the booted coordinator as events, and after each the plan it publishes
// must give UI, Pilot and DockingController the holders of Abb. 5.4 — the table the offline
// scenario coordinator/applets/scenarios/real_world_5_3.yaml expects too. The modules that stand
// for the hardware run exactly while their service is held.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/config_client.hpp"
#include "plan_watch.hpp"
#include "source_tree.hpp"

namespace oscar {
namespace {

using ::testing::HasSubstr;
using Holders = std::map<std::string, std::string>;  // service -> the plan's holder

std::string system_5_3() {
  std::ifstream in(oscar::testing::source_path("config/applets-5-3.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class Scenario {
 public:
  Scenario()
      : sys("applets_5_3", system_5_3()),
        plans_(sys.participant()),
        operator_(sys.participant(), "boot") {}

  // The world's event for an applet's bundle, through the coordinator's command port.
  ::testing::AssertionResult event(const std::string& applet, const std::string& bundle,
                                   const std::string& what) {
    AppletEvent e;
    e.applet(applet);
    e.bundle(bundle);
    e.event(what);
    const auto reply = operator_.command("coordinator", "coordinator", "applet", e);
    if (reply.ok()) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << applet << "/" << bundle << " " << what << ": " << reply.error();
  }

  // Waits until the plan gives each service the expected holder.
  ::testing::AssertionResult plan_shows(const Holders& expected) {
    const auto matches = [&](const AppletPlan& p) {
      for (const auto& [service, holder] : expected) {
        if (planned(p, service) != holder) return false;
      }
      return true;
    };
    if (plans_.wait(matches)) return ::testing::AssertionSuccess();
    auto failure = ::testing::AssertionFailure();
    for (const auto& [service, holder] : expected)
      failure << service << ": expected " << holder << "; ";
    return failure << "the plan says " << plans_.last_json() << "\nboot output:\n"
                   << sys.boot_output();
  }

  // The module's kernel (named like the module) reaches `mode`.
  void wait_module(const std::string& module, const std::string& mode) {
    sys.wait_for([&](const SystemState& st) {
      const auto* m = test::entry(st, module);
      const auto* k = m ? test::kernel_state(*m, module) : nullptr;
      return k && k->mode() == mode;
    });
  }

  test::BootedSystem sys;

 private:
  static std::string planned(const AppletPlan& p, const std::string& service) {
    for (const auto& s : p.services()) {
      if (s.name() == service) return s.plan();
    }
    return "(no such service)";
  }

  test::PlanWatch plans_;
  ConfigClient operator_;
};

TEST(Applets53, TheLiveSystemFollowsTheHoldersOfAbb54StepByStep) {
  Scenario s;
  s.sys.running();
  // 1. Start of the application: UIService takes monitor and mouse, the menu the UI.
  ASSERT_TRUE(s.plan_shows({{"UI", "Menu"}, {"Pilot", "undef"}, {"DockingController", "undef"}}));
  s.wait_module("monitor", "continuous");
  s.wait_module("pilot", "deactivated");
  // 2. The user opens Drive-To from the menu and sets a task.
  ASSERT_TRUE(s.event("DriveTo", "task", "request"));
  ASSERT_TRUE(s.event("DriveTo", "task", "trigger"));
  ASSERT_TRUE(
      s.plan_shows({{"UI", "DriveTo"}, {"Pilot", "DriveTo"}, {"DockingController", "blocked"}}));
  s.wait_module("pilot", "continuous");
  // 3. The battery runs low during the task: the battery applet steps in.
  ASSERT_TRUE(s.event("Battery", "charge", "request"));
  ASSERT_TRUE(s.event("Battery", "charge", "trigger"));
  ASSERT_TRUE(
      s.plan_shows({{"UI", "Battery"}, {"Pilot", "blocked"}, {"DockingController", "Battery"}}));
  s.wait_module("docking", "continuous");
  s.wait_module("battery", "continuous");
  // `oscar applets graph` draws this plan: who holds what, and what the docking controller needs.
  const auto svg = test::temp_path("applets_5_3") + ".svg";
  test::Process graph({test::bin("oscar-applets"), "graph", "-o", svg, "-d",
                       std::to_string(s.sys.domain()), "--timeout", "10"},
                      test::temp_path("applets_5_3_graph") + ".out");
  ASSERT_EQ(graph.wait(std::chrono::seconds(30)), 0) << graph.output();
  std::stringstream dot;
  dot << std::ifstream(svg + ".dot").rdbuf();
  EXPECT_THAT(dot.str(), HasSubstr(R"("a:Battery" -> "s:DockingController" [color=darkgreen)"));
  EXPECT_THAT(dot.str(), HasSubstr(R"("a:DriveTo" -> "s:Pilot" [color=grey, style=dashed)"));
  EXPECT_THAT(dot.str(), HasSubstr(R"("s:DockingController" -> "s:Pilot" [style=bold)"));
  EXPECT_THAT(dot.str(), HasSubstr(R"("s:UI" -> "a:UIService" [dir=back)"));
  EXPECT_TRUE(std::filesystem::exists(svg));
  std::filesystem::remove(svg);
  std::filesystem::remove(svg + ".dot");
  // 4. Charged: the drive-to task goes on.
  ASSERT_TRUE(s.event("Battery", "charge", "release"));
  ASSERT_TRUE(
      s.plan_shows({{"UI", "DriveTo"}, {"Pilot", "DriveTo"}, {"DockingController", "blocked"}}));
  s.wait_module("docking", "deactivated");
  // 5. An appointment is due during the task.
  ASSERT_TRUE(s.event("Calendar", "appointment", "request"));
  ASSERT_TRUE(s.event("Calendar", "appointment", "trigger"));
  ASSERT_TRUE(
      s.plan_shows({{"UI", "Calendar"}, {"Pilot", "Calendar"}, {"DockingController", "blocked"}}));
  // 6. The user confirms it: the task goes on once more.
  ASSERT_TRUE(s.event("Calendar", "appointment", "release"));
  ASSERT_TRUE(
      s.plan_shows({{"UI", "DriveTo"}, {"Pilot", "DriveTo"}, {"DockingController", "blocked"}}));
  // 7. The home button: the drive-to view closes and the menu opens.
  ASSERT_TRUE(s.event("DriveTo", "task", "release"));
  ASSERT_TRUE(s.event("Menu", "ui", "trigger"));
  ASSERT_TRUE(s.plan_shows({{"UI", "Menu"}, {"Pilot", "undef"}, {"DockingController", "undef"}}));
  s.wait_module("pilot", "deactivated");
}

}  // namespace
}  // namespace oscar
