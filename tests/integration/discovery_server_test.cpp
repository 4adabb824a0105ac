// Systems whose participants find each other through discovery servers that boot starts
// (`network: { discovery: server }`, docs/network.md).
#include <signal.h>

#include <fstream>
#include <iterator>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::entry;
using ::testing::HasSubstr;

std::string system_yaml(const std::string& name, const std::string& network) {
  return "system: " + name + "\nlease: 1s\nnetwork: " + network + R"(
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
  - name: sink
    kernels: [ { type: bench_sink, name: sink, params: { type: Bool }, inputs: { in: src/out } } ]
    mode: single_step
    restart: { policy: auto, max: 5, backoff: 50ms }
)";
}

std::uint64_t sink_cycles(const SystemState& s) {
  const auto* k = test::kernel_state(*entry(s, "sink"), "sink");
  return k ? k->cycles() : 0;
}

// The pid of the system's discovery server `index` (its command line names the system file).
long server_pid(const std::string& file, int index) {
  for (const auto pid : test::processes_mentioning(file)) {
    const auto cmd = test::proc_file(pid, "cmdline");
    if (cmd.find("oscar-discovery-server") != std::string::npos &&
        cmd.find(std::string("--index") + '\0' + std::to_string(index) + '\0') !=
            std::string::npos) {
      return pid;
    }
  }
  return -1;
}

// Kills the sink and waits until its next incarnation runs and has cues of the source again:
// it found the source, and the registry found it, through the discovery server(s).
void kill_sink_and_see_it_rejoin(BootedSystem& sys, unsigned incarnation) {
  const auto before = sys.wait_for([](const SystemState& st) { return sink_cycles(st) > 0; });
  ASSERT_EQ(kill(static_cast<pid_t>(entry(before, "sink")->pid()), SIGKILL), 0);
  const auto s = sys.wait_for(
      [&](const SystemState& st) {
        const auto* sink = entry(st, "sink");
        return sink->incarnation() == incarnation && sink->status() == "running" &&
               st.state() == "running" && sink_cycles(st) > 10;
      },
      30s);
  EXPECT_EQ(entry(s, "sink")->incarnation(), incarnation) << sys.boot_output();
}

TEST(DiscoveryServer, ASystemBootsOnItsServerCuesFlowAndARestartedModuleRejoins) {
  BootedSystem sys("ds_one", system_yaml("ds_one", "{ discovery: server }"));
  auto s = sys.running();
  ASSERT_EQ(s.state(), "running") << sys.boot_output();
  ASSERT_GT(server_pid(sys.file(), 0), 0) << "boot started no discovery server";
  EXPECT_EQ(server_pid(sys.file(), 1), -1) << "one server unless two are named";
  kill_sink_and_see_it_rejoin(sys, 2);
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
  EXPECT_EQ(server_pid(sys.file(), 0), -1) << "the server outlived the system";
}

TEST(DiscoveryServer, WithTwoServersTheSystemKeepsDiscoveringWhileOneIsGone) {
  BootedSystem sys("ds_two", system_yaml("ds_two",
                                         "{ discovery: server, discovery_servers: "
                                         "[127.0.0.1, 127.0.0.1] }"));
  sys.running();
  const long first = server_pid(sys.file(), 0);
  ASSERT_GT(first, 0);
  ASSERT_GT(server_pid(sys.file(), 1), 0);
  // A stopped server answers nobody and is not restarted: only the other one serves.
  ASSERT_EQ(kill(static_cast<pid_t>(first), SIGSTOP), 0);
  kill_sink_and_see_it_rejoin(sys, 2);
  ASSERT_EQ(kill(static_cast<pid_t>(first), SIGCONT), 0);
  // A killed server is started again by boot, and the system goes on discovering.
  ASSERT_EQ(kill(static_cast<pid_t>(first), SIGKILL), 0);
  kill_sink_and_see_it_rejoin(sys, 3);
  EXPECT_THAT(sys.boot_output(), HasSubstr("restarting discovery-server-0"));
  const long second = server_pid(sys.file(), 0);
  EXPECT_GT(second, 0);
  EXPECT_NE(second, first);
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
}

}  // namespace
}  // namespace oscar
