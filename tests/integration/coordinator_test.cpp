// The coordinator in a booted system (docs/coordinator.md): granting a service activates its
// provider module, releasing it deactivates it, a higher priority preempts and the old holder's
// command is refused naming the new holder, `oscar applets ps --json` shows the plan, and a
// restarted provider gets its holder's configuration back.
#include <signal.h>

#include <condition_variable>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "coordinated_system.hpp"
#include "oscar/config_client.hpp"
#include "oscar/coordinator/plan_json.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar {
namespace {

using test::camera_system;
using test::CoordinatedSystem;
using test::entry;
using ::testing::HasSubstr;

using Strings = std::vector<std::string>;

TEST(Coordinator, AnAppletsRequestActivatesTheProviderAndReleasingDeactivatesIt) {
  CoordinatedSystem c("coord_grant");
  c.sys.running();
  c.wait_plan([](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera").empty(); },
              "Camera idle");
  c.wait_cam_mode("deactivated");

  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera held by low");
  c.wait_cam_mode("continuous");
  // The holder's command reached the framegrabber through the coordinator.
  EXPECT_TRUE(c.logged("applet low: frame mode -> quarter"));

  ASSERT_TRUE(c.accepted("low", "release"));
  c.wait_plan([](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera").empty(); },
              "Camera released");
  c.wait_cam_mode("deactivated");
}

TEST(Coordinator, AHigherPriorityPreemptsAndTheOldHoldersCommandIsRefusedNamingTheNewHolder) {
  CoordinatedSystem c("coord_preempt");
  c.sys.running();
  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera held by low");
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"};
      },
      "Camera held by high");
  EXPECT_TRUE(c.logged("applet high: frame mode -> half"));
  EXPECT_TRUE(
      c.logged("applet low: frame mode quarter refused: applet 'low' does not hold "
               "service 'Camera': it is held by 'high'"));

  // oscar applets ps --json shows the holder, the access and who waits.
  test::Process ps({test::bin("oscar-applets"), "ps", "--json", "-d",
                    std::to_string(c.sys.domain()), "--timeout", "10"},
                   test::temp_path("coord_ps") + ".out");
  ASSERT_EQ(ps.wait(std::chrono::seconds(30)), 0) << ps.output();
  const auto j = nlohmann::json::parse(ps.output());
  EXPECT_EQ(j["services"]["Camera"]["holders"], nlohmann::json::array({"high"}));
  EXPECT_EQ(j["services"]["Camera"]["access"], "exclusive");
  EXPECT_EQ(j["services"]["Camera"]["waiting"], nlohmann::json::array({"low"}));
  ASSERT_EQ(j["applets"].size(), 2u);
  EXPECT_EQ(j["applets"][0]["name"], "low");
  EXPECT_EQ(j["applets"][0]["process"], "coordinator");
  EXPECT_EQ(j["applets"][0]["state"], "waiting");
  EXPECT_EQ(j["applets"][1]["state"], "holding");

  // When the higher priority lets go, the old holder gets the camera back.
  ASSERT_TRUE(c.accepted("high", "release"));
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera back with low");
  c.wait_cam_mode("continuous");
}

TEST(Coordinator, AFailedProviderTakesTheServiceAwayAndTheRestartGivesItBackConfigured) {
  CoordinatedSystem c("coord_restart");
  c.sys.running();
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"};
      },
      "Camera held by high");
  ASSERT_TRUE(c.logged("applet high: frame mode -> half"));
  const auto s = c.sys.wait_for([](const SystemState& st) { return entry(st, "cam") != nullptr; });
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "cam")->pid()), SIGKILL), 0);
  EXPECT_TRUE(c.logged("coordinator: service Camera is unavailable"));
  c.sys.wait_for([](const SystemState& st) {
    const auto* m = entry(st, "cam");
    return m && m->incarnation() == 2 && m->status() == "running";
  });
  EXPECT_TRUE(c.logged("coordinator: service Camera is available again"));
  c.wait_cam_mode("continuous");
  // What the holder commanded before the failure, sent again to the new process.
  EXPECT_TRUE(c.logged("coordinator: Camera: cam/cam frame_mode re-applied after the restart: ok"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"};
      },
      "Camera held by high again");
}

// The registry supervises the coordinator like any module. A restarted coordinator starts
// with nothing granted: no module stays configured for a holder that lost its service.
TEST(Coordinator, AKilledCoordinatorIsRestartedAndIdlesWhatItsHoldersLost) {
  CoordinatedSystem c("coord_killed");
  c.sys.running();
  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_cam_mode("continuous");
  const auto s =
      c.sys.wait_for([](const SystemState& st) { return entry(st, "coordinator") != nullptr; });
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "coordinator")->pid()), SIGKILL), 0);
  c.sys.wait_for([](const SystemState& st) {
    const auto* m = entry(st, "coordinator");
    return m && m->incarnation() == 2 && m->status() == "running";
  });
  c.wait_cam_mode("deactivated");
  c.wait_plan([](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera").empty(); },
              "Camera idle after the restart");
  // And it grants again.
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_cam_mode("continuous");
}

TEST(Coordinator, AnEventForAnUnknownBundleIsRefusedWithTheReason) {
  CoordinatedSystem c("coord_bad_event");
  c.sys.running();
  const auto reply = c.event("nobody", "request");
  EXPECT_FALSE(reply.ok());
  EXPECT_THAT(reply.error(), HasSubstr("unknown applet 'nobody'"));
}

// The command port takes the scheduler's vocabulary for applets in the coordinator's process
// too; crash only for applets in a process of their own.
TEST(Coordinator, ASetPriorityEventReachesALocalAppletAndItsCrashIsRefused) {
  CoordinatedSystem c("coord_local_events");
  c.sys.running();
  ASSERT_TRUE(c.accepted("high", "request"));
  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"};
      },
      "Camera held by high");
  AppletEvent raise;
  raise.applet("low");
  raise.bundle("camera");
  raise.event("set_priority");
  raise.priority(350);  // above high (300)
  const auto reply = c.command(raise);
  ASSERT_TRUE(reply.ok()) << reply.error();
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera taken by low at priority 350");
  const auto crash = c.event("low", "crash");
  EXPECT_FALSE(crash.ok());
  EXPECT_THAT(crash.error(), HasSubstr("event 'crash' is for applets in a process of their own"));
}

// Applets in other processes (docs/coordinator.md): the camera system with `applet` in a
// process of its own, "applets", an applet lease of 1 s and a module lease long enough that the
// applet lease, not the registry, is what takes a hung applet's service.
std::string remote_system(const std::string& applet, bool requested_at_start = false) {
  auto yaml = camera_system();
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = yaml.find(from);
    if (at == std::string::npos) throw std::logic_error("the example changed: no " + from);
    yaml.replace(at, from.size(), to);
  };
  replace("domain: 44\n", "domain: 44\nlease: 3s\n");
  replace("coordinator:\n", "coordinator:\n  applet_lease: 1s\n");
  replace("      name: " + applet + "\n", "      name: " + applet + "\n      process: applets\n");
  if (requested_at_start) {
    const std::string bundle = "priority: " + std::string(applet == "high" ? "high" : "low") +
                               ", resources: [ { service: Camera } ]";
    replace(bundle, bundle + ", requested: true");
  }
  return yaml;
}

bool present(const AppletPlan& p, const std::string& applet, const std::string& state) {
  return CoordinatedSystem::applet(p, applet) == "applets " + state;
}

TEST(RemoteApplet, AcquiresTheServiceAndItsCommandReachesTheModuleThenReleasesIt) {
  CoordinatedSystem c("remote_grant", remote_system("high"));
  c.sys.running();
  // It announced itself from its process (oscar applets ps shows the process).
  c.wait_plan([](const AppletPlan& p) { return present(p, "high", "idle"); },
              "high announced from process applets");
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"} &&
               present(p, "high", "holding");
      },
      "Camera held by the remote high");
  c.wait_cam_mode("continuous");
  // Its command went over DDS to the coordinator, which forwarded it to the framegrabber.
  EXPECT_TRUE(c.logged("applet high: frame mode -> half"));

  test::Process ps({test::bin("oscar-applets"), "ps", "--json", "-d",
                    std::to_string(c.sys.domain()), "--timeout", "10"},
                   test::temp_path("remote_ps") + ".out");
  ASSERT_EQ(ps.wait(std::chrono::seconds(30)), 0) << ps.output();
  const auto j = nlohmann::json::parse(ps.output());
  ASSERT_EQ(j["applets"].size(), 2u);
  EXPECT_EQ(j["applets"][0]["process"], "coordinator");
  EXPECT_EQ(j["applets"][1]["name"], "high");
  EXPECT_EQ(j["applets"][1]["process"], "applets");

  ASSERT_TRUE(c.accepted("high", "release"));
  c.wait_plan([](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera").empty(); },
              "Camera released by the remote high");
  c.wait_cam_mode("deactivated");
}

// The command port answers an event for a remote applet once the applet has made the call: a
// call the scheduler refuses is the event's refusal, and the events of the scheduler's whole
// vocabulary reach it (here set_priority, which the plan then follows).
TEST(RemoteApplet, AnEventIsAnsweredAfterTheAppletsCallAndCarriesItsRefusal) {
  CoordinatedSystem c("remote_event", remote_system("low"));
  c.sys.running();
  c.wait_plan([](const AppletPlan& p) { return present(p, "low", "idle"); },
              "low announced from process applets");
  const auto refused = c.event("low", "trigger");  // not requested: the scheduler refuses
  EXPECT_FALSE(refused.ok());
  EXPECT_THAT(refused.error(), HasSubstr("low"));
  EXPECT_THAT(refused.error(), HasSubstr("camera"));
  ASSERT_TRUE(c.accepted("high", "request"));
  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"};
      },
      "Camera held by high");
  AppletEvent raise;
  raise.applet("low");
  raise.bundle("camera");
  raise.event("set_priority");
  raise.priority(350);  // above high (300)
  const auto reply = c.command(raise);
  ASSERT_TRUE(reply.ok()) << reply.error();
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera taken by low at priority 350");
  const auto unknown = c.event("low", "fly");
  EXPECT_FALSE(unknown.ok());
  EXPECT_THAT(unknown.error(),
              HasSubstr("unknown event 'fly' (events: request, release, trigger, "
                        "yield, set_priority, set_deadline, negotiate, crash, add, remove)"));
}

TEST(RemoteApplet, ARemoteHigherPriorityPreemptsALocalHolderWhoseCommandIsThenRefused) {
  CoordinatedSystem c("remote_preempts", remote_system("high"));
  c.sys.running();
  c.wait_plan([](const AppletPlan& p) { return present(p, "high", "idle"); }, "high announced");
  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera held by the local low");
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"};
      },
      "Camera taken by the remote high");
  EXPECT_TRUE(c.logged("applet high: frame mode -> half"));
  EXPECT_TRUE(
      c.logged("applet low: frame mode quarter refused: applet 'low' does not hold "
               "service 'Camera': it is held by 'high'"));
}

TEST(RemoteApplet, ALocalHigherPriorityPreemptsARemoteHolderWhoseCommandIsThenRefused) {
  CoordinatedSystem c("remote_preempted", remote_system("low"));
  c.sys.running();
  c.wait_plan([](const AppletPlan& p) { return present(p, "low", "idle"); }, "low announced");
  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera held by the remote low");
  EXPECT_TRUE(c.logged("applet low: frame mode -> quarter"));
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"} &&
               present(p, "low", "waiting");
      },
      "Camera taken from the remote low");
  // The remote applet (insist: true) keeps sending; the coordinator refuses naming the holder.
  EXPECT_TRUE(
      c.logged("applet low: frame mode quarter refused: applet 'low' does not hold "
               "service 'Camera': it is held by 'high'"));
}

TEST(RemoteApplet, AKilledRemoteHoldersServiceGoesToTheWaitingAppletWithinTheLease) {
  CoordinatedSystem c("remote_killed", remote_system("high"));
  c.sys.running();
  c.wait_plan([](const AppletPlan& p) { return present(p, "high", "idle"); }, "high announced");
  ASSERT_TRUE(c.accepted("low", "request"));
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"} &&
               present(p, "high", "holding");
      },
      "Camera held by the remote high, low waiting");
  const auto s = c.sys.wait_for([](const SystemState& st) { return entry(st, "applets"); });
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "applets")->pid()), SIGKILL), 0);
  // The lease runs out, or the restarted process announces a new session first (the registry
  // restarts it after 200 ms): either way what the dead process held is taken.
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera given to the waiting low");
  EXPECT_TRUE(c.logged("applet low: frame mode -> quarter"));
  // The registry restarts the process; the applet announces itself again (asking for nothing:
  // its request was an event, gone with the process) and low keeps the camera.
  c.wait_plan(
      [](const AppletPlan& p) {
        return present(p, "high", "idle") &&
               CoordinatedSystem::holders(p, "Camera") == Strings{"low"};
      },
      "high back, idle");
}

TEST(RemoteApplet, AHungRemoteHolderLosesItsGrantByLeaseAndAsksAgainWhenItGoesOn) {
  CoordinatedSystem c("remote_hung", remote_system("high", /*requested_at_start=*/true));
  c.sys.running();
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"};
      },
      "Camera held by the remote high (requested at start)");
  ASSERT_TRUE(c.accepted("low", "request"));
  const auto s = c.sys.wait_for([](const SystemState& st) { return entry(st, "applets"); });
  const auto pid = static_cast<pid_t>(entry(s, "applets")->pid());
  ASSERT_EQ(kill(pid, SIGSTOP), 0);
  const bool lost = c.logged("coordinator: applet 'high' in process 'applets' missed its lease");
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera given to the waiting low while high hangs");
  ASSERT_EQ(kill(pid, SIGCONT), 0);
  EXPECT_TRUE(lost);
  // It goes on (or the registry restarted it): it announces itself with its request again, and
  // its priority takes the camera back.
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"high"} &&
               present(p, "high", "holding");
      },
      "Camera back with high");
}

TEST(RemoteApplet, ARestartedCoordinatorRebuildsThePlanFromTheRemoteAppletsRequests) {
  CoordinatedSystem c("remote_coord_killed", remote_system("high"));
  c.sys.running();
  c.wait_plan([](const AppletPlan& p) { return present(p, "high", "idle"); }, "high announced");
  ASSERT_TRUE(c.accepted("high", "request"));
  c.wait_cam_mode("continuous");
  const auto s =
      c.sys.wait_for([](const SystemState& st) { return entry(st, "coordinator") != nullptr; });
  const auto killed_at = static_cast<unsigned long long>(wall_now());
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "coordinator")->pid()), SIGKILL), 0);
  c.sys.wait_for([](const SystemState& st) {
    const auto* m = entry(st, "coordinator");
    return m && m->incarnation() == 2 && m->status() == "running";
  });
  // The remote applet kept its request; the new coordinator hears it announced again.
  c.wait_plan(
      [&](const AppletPlan& p) {
        return p.stamp_ns() > killed_at &&
               CoordinatedSystem::holders(p, "Camera") == Strings{"high"} &&
               present(p, "high", "holding");
      },
      "Camera held by high again after the coordinator's restart");
  c.wait_cam_mode("continuous");
}

// A trigger of a single-step kernel goes the same way as a command: CobraControl in a process
// of its own grabs frames from a camera that runs only when triggered.
TEST(RemoteApplet, ARemoteAppletsTriggersReachTheSingleStepKernelItHolds) {
  test::BootedSystem sys("remote_trigger", R"(system: remote_trigger
modules:
  - name: cam
    kernels: [ { type: framegrabber, name: cam, params: { source: "synthetic:static" } } ]
    mode: deactivated
services:
  Camera:
    provided_by: [cam/cam]
    access: exclusive
    granted: { activate: "single_step:command" }
    idle: deactivate
coordinator:
  applets:
    - type: cobra_control
      name: cobra
      process: applets
      params: { cameras: 'Camera:cam/cam', cycle_ms: 100 }
      bundles: [ { name: cameras, requested: true, resources: [ { service: Camera } ] } ]
)");
  sys.running();
  sys.wait_for([](const SystemState& st) {
    const auto* m = entry(st, "cam");
    const auto* k = m ? test::kernel_state(*m, "cam") : nullptr;
    return k && k->mode() == "single_step" && k->cycles() >= 5;
  });
  EXPECT_THAT(sys.boot_output(), ::testing::Not(HasSubstr("refused")));
}

// `oscar applets ps` tells a coordinator that offers its plan but sends none (hung) from none.
TEST(Coordinator, AppletsPsNamesACoordinatorThatSendsNoPlan) {
  testing::FreeDomain domain;
  DdsParticipant participant(domain.domain(), "test:hung_coordinator");
  TopicWriter<AppletPlan, AppletPlanPubSubType> silent(participant, topics::applet_plan());
  test::Process ps(
      {test::bin("oscar-applets"), "ps", "-d", std::to_string(domain.domain()), "--timeout", "1.5"},
      test::temp_path("hung_ps") + ".out");
  EXPECT_EQ(ps.wait(std::chrono::seconds(30)), 1) << ps.output();
  EXPECT_THAT(ps.output(), HasSubstr(fmt::format("oscar applets: the coordinator on domain {} "
                                                 "offers its plan but sent none within 3.0 s",
                                                 domain.domain())));
}

}  // namespace
}  // namespace oscar
