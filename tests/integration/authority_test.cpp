// Only the coordinator configures (docs/architecture.md, "Configuration"): the authority comes from
// the process a command is written from, not from the name it claims. A kernel that claims to be
// the coordinator (what the retired sequencer did) is refused; a process hosting no module of the
// system (boot, the registry, an operator's tool) still acts under the name it gives.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <condition_variable>
#include <fstream>
#include <iterator>
#include <mutex>
#include <optional>

#include "booted_system.hpp"
#include "oscar/config_client.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "source_tree.hpp"

namespace oscar {
namespace {

using test::entry;
using ::testing::HasSubstr;

// `params`: what the impostor claims to be and tries (by default: the coordinator activating cam).
std::string system_with_an_impostor(const std::string& params = "target: cam") {
  return std::string("system: authority\nplugins: ") +
         oscar::testing::build_path("lib/oscar/test_plugins") + R"(
modules:
  - name: cam
    kernels: [ { type: framegrabber, name: cam, params: { source: "synthetic:static" } } ]
    mode: deactivated
  - name: rogue
    kernels:
      - { type: test_impostor, name: rogue, params: { )" +
         params + R"( }, mode: "continuous:300ms" }
)";
}

std::string cam_mode(const SystemState& s) {
  const auto* m = entry(s, "cam");
  const auto* k = m ? test::kernel_state(*m, "cam") : nullptr;
  return k ? k->mode() : "";
}

TEST(Authority, AKernelClaimingTheCoordinatorsNameFromItsModulesProcessIsRefused) {
  test::BootedSystem sys("authority_impostor", system_with_an_impostor());
  sys.running();
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  const std::string refusal =
      "impostor: refused: 'coordinator' may not activate module 'cam': the command comes from "
      "the process of module 'rogue'";
  while (sys.boot_output().find(refusal) == std::string::npos &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_THAT(sys.boot_output(), HasSubstr(refusal));
  EXPECT_THAT(sys.boot_output(), ::testing::Not(HasSubstr("impostor: accepted")));
  EXPECT_EQ(cam_mode(sys.registry().latest().value_or(SystemState{})), "deactivated");
}

TEST(Authority, AProcessHostingNoModuleActsUnderTheNameItGives) {
  test::BootedSystem sys("authority_operator", system_with_an_impostor());
  sys.running();
  ConfigClient operator_tool(sys.participant(), "coordinator");
  const auto reply = operator_tool.send("cam", CMD_ACTIVATE, {"*", "continuous:100ms"});
  ASSERT_TRUE(reply.ok()) << reply.error();
  sys.wait_for([](const SystemState& s) { return cam_mode(s) == "continuous"; });
}

// A module's process may not ask the registry to shut the system down, whatever name it gives.
TEST(Authority, AModulesProcessMayNotShutTheSystemDown) {
  test::BootedSystem sys("authority_shutdown",
                         system_with_an_impostor("target: cam, claim: boot, ask: shutdown"));
  sys.running();
  const std::string refusal =
      "refused: 'boot' may not shut the system down: the request comes from the process of "
      "module 'rogue', and only boot and operator tools";
  const auto registry_log = [&] {
    std::ifstream in(sys.log_dir() + "/registry.log");
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (registry_log().find(refusal) == std::string::npos &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_THAT(registry_log(), HasSubstr(refusal));
  std::this_thread::sleep_for(std::chrono::seconds(1));  // the impostor asked again meanwhile
  EXPECT_EQ(sys.registry().latest().value_or(SystemState{}).state(), "running");
}

// Launch by name: whoever writes a launch request names a module, never a command. A request to
// start what is no module of the monitor's system file is refused with the reason, and nothing
// is started.
TEST(Authority, AMonitorStartsOnlyModulesOfItsSystemFile) {
  test::BootedSystem sys("authority_launch", system_with_an_impostor());
  sys.running();
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<MonitorBeat> monitor;
  std::vector<ProcessEvent> events;
  TopicReader<MonitorBeat, MonitorBeatPubSubType> beats(
      sys.participant(), topics::monitor_alive(std::chrono::seconds(60)),
      [&](const MonitorBeat& b, const auto&) {
        std::lock_guard lock(mutex);
        monitor = b;
        changed.notify_all();
      });
  TopicReader<ProcessEvent, ProcessEventPubSubType> process_events(
      sys.participant(), topics::process_events(), [&](const ProcessEvent& e, const auto&) {
        std::lock_guard lock(mutex);
        events.push_back(e);
        changed.notify_all();
      });
  {
    std::unique_lock lock(mutex);
    ASSERT_TRUE(
        changed.wait_for(lock, std::chrono::seconds(10), [&] { return monitor.has_value(); }));
  }
  TopicWriter<LaunchRequest, LaunchRequestPubSubType> launch(sys.participant(), topics::launch());
  for (auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
       launch.matched() == 0 && std::chrono::steady_clock::now() < until;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  LaunchRequest q;
  q.id(1'000'000);  // far from the registry's own ids
  q.host(monitor->host());
  q.monitor_pid(monitor->pid());
  q.kind(LAUNCH_START);
  q.module_name("sh -c 'touch /tmp/oscar_authority_pwned'");
  q.incarnation(1);
  launch.write(q);
  const auto about_it = [&](const ProcessEvent& e) { return e.module_name() == q.module_name(); };
  std::unique_lock lock(mutex);
  ASSERT_TRUE(changed.wait_for(lock, std::chrono::seconds(10), [&] {
    return std::any_of(events.begin(), events.end(), about_it);
  })) << "the monitor did not answer the request";
  const auto e = *std::find_if(events.begin(), events.end(), about_it);
  EXPECT_EQ(e.kind(), PROC_START_FAILED);
  EXPECT_THAT(e.detail(), HasSubstr("has no module of that name"));
  EXPECT_EQ(e.pid(), 0);
}

}  // namespace
}  // namespace oscar
