// A module started under gdbserver from the system file (`debug: { gdbserver: PORT }`), with a
// real gdb attached: held at a breakpoint it is not taken for hung, and its crash still counts.
// Labelled `debugger`, not `integration`: the sanitizer passes leave it out, because
// LeakSanitizer cannot work in a process that gdbserver already traces, and ThreadSanitizer's
// runtime under ptrace is not what these tests are about (docs/boot.md, "Debugging a module").
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/registryPubSubTypes.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::entry;
using ::testing::HasSubstr;

/// The program's path if it is on $PATH.
std::optional<std::string> on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const auto candidate = std::filesystem::path(dir) / program;
    if (!dir.empty() && access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return std::nullopt;
}

/// A TCP port on 127.0.0.1 that nothing listens on now (the kernel's choice).
int free_loopback_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  const bool ok = bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
                  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  close(fd);
  return ok ? ntohs(a.sin_port) : 0;
}

std::string with_port(std::string yaml, int port) {
  yaml.replace(yaml.find("PORT"), 4, std::to_string(port));
  return yaml;
}

/// gdb in batch mode, connected to the module's gdbserver, running `commands` in order.
std::vector<std::string> gdb_batch(const std::string& gdb, int port,
                                   const std::vector<std::string>& commands) {
  std::vector<std::string> argv{gdb, "--batch", "-nx"};
  for (const auto* setup : {"set pagination off", "set sysroot /", "set breakpoint pending on",
                            "set tcp connect-timeout 60", "handle SIGPIPE nostop noprint pass"}) {
    argv.insert(argv.end(), {"-ex", setup});
  }
  argv.insert(argv.end(), {"-ex", "target remote 127.0.0.1:" + std::to_string(port)});
  for (const auto& c : commands) argv.insert(argv.end(), {"-ex", c});
  return argv;
}

/// gdb's path if both gdb and gdbserver are installed.
std::optional<std::string> find_gdb() {
  if (!on_path("gdbserver")) return std::nullopt;
  return on_path("gdb");
}

constexpr const char* kSkip =
    "gdb and gdbserver are needed (Debian packages gdb, gdbserver; scripts/setup.sh installs them)";

// Deactivated until the test activates it, so the breakpoint is reached only once heartbeats flow
// (the registry gives a module that has sent none a longer grace than the lease).
constexpr const char* kHeld = R"(
system: debugged
lease: 300ms
modules:
  - name: held
    kernels: [ { type: bench_source, name: held, params: { type: Bool } } ]
    mode: deactivated
    restart: { policy: auto, max: 3, backoff: 50ms }
    debug: { gdbserver: PORT }
)";

TEST(Debugger, AModuleHeldAtABreakpointKeepsItsIncarnationAndPsShowsDebug) {
  const auto gdb_program = find_gdb();
  if (!gdb_program) GTEST_SKIP() << kSkip;
  const int port = free_loopback_port();
  ASSERT_GT(port, 0);
  BootedSystem sys("debugger_held", with_port(kHeld, port));
  // Held at the first process() for twice the lease (300 ms), then let go.
  test::Process gdb(gdb_batch(*gdb_program, port,
                              {"break oscar::modules::BenchSource::process", "continue",
                               "echo oscar-test: held\\n", "shell sleep 0.6", "delete",
                               "echo oscar-test: released\\n", "continue"}),
                    test::temp_path("debugger_held_gdb") + ".log");
  auto s = sys.running();
  ASSERT_NE(entry(s, "held"), nullptr);
  EXPECT_EQ(entry(s, "held")->debug(), "gdbserver 127.0.0.1:" + std::to_string(port));

  // The module's heartbeats reach this process, so they reach the registry as well.
  DdsParticipant participant(test::test_domain(), "test:debugger_beats");
  std::atomic<bool> beating{false};
  TopicReader<ModuleBeat, ModuleBeatPubSubType> beats(
      participant, "oscar/registry/alive", qos::beat_reader(300ms),
      [&](const ModuleBeat& b, const auto&) {
        if (b.module_name() == "held" && b.incarnation() == 1) beating = true;
      });
  ASSERT_TRUE(eventually([&] { return beating.load(); }, 30s)) << "no heartbeat from 'held'";

  // The reply may wait until gdb lets the module go: all its threads stop at the breakpoint.
  EXPECT_TRUE(sys.configure("held", CMD_ACTIVATE, {"held", "continuous:20ms"}, 20s).ok());
  const auto gdb_said = [&](const std::string& text) {
    return eventually([&] { return gdb.output().find(text) != std::string::npos; }, 60s, 20ms);
  };
  ASSERT_TRUE(gdb_said("oscar-test: held")) << "gdb output:\n" << gdb.output();
  ASSERT_TRUE(gdb_said("oscar-test: released")) << "gdb output:\n" << gdb.output();

  // It runs on after the breakpoint, in the same process.
  s = sys.wait_for([](const SystemState& st) {
    const auto* m = entry(st, "held");
    return m->incarnation() != 1 || m->status() != "running" ||
           (!m->state().kernels().empty() && m->state().kernels()[0].cycles() >= 5);
  });
  const auto* held = entry(s, "held");
  EXPECT_EQ(held->incarnation(), 1u) << held->last_failure() << "\ngdb output:\n" << gdb.output();
  EXPECT_EQ(held->status(), "running");
  EXPECT_EQ(held->restarts(), 0u);
  EXPECT_EQ(held->last_failure(), "");
  EXPECT_EQ(s.state(), "running") << s.message();
  std::ifstream registry_log(sys.log_dir() + "/registry.log");
  const std::string registry_said((std::istreambuf_iterator<char>(registry_log)), {});
  EXPECT_THAT(registry_said, HasSubstr("so it is not taken for hung"));

  const auto domain = std::to_string(test::test_domain());
  test::Process ps({test::bin("oscar-ps"), "--domain", domain},
                   test::temp_path("debugger_ps") + ".log");
  ASSERT_EQ(ps.wait(30s), 0) << ps.output();
  EXPECT_THAT(ps.output(), HasSubstr("debug: gdbserver 127.0.0.1:" + std::to_string(port)));
  test::Process ps_json({test::bin("oscar-ps"), "--domain", domain, "--json"},
                        test::temp_path("debugger_ps_json") + ".log");
  ASSERT_EQ(ps_json.wait(30s), 0) << ps_json.output();
  const auto j = nlohmann::json::parse(ps_json.output());
  EXPECT_EQ(j["modules"][0]["debug"], "gdbserver 127.0.0.1:" + std::to_string(port));
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
}

constexpr const char* kCrashing = R"(
system: debugged_crash
lease: 300ms
modules:
  - name: crashing
    kernels: [ { type: bench_source, name: crashing, params: { type: Bool } } ]
    mode: { continuous: 20ms }
    restart: { policy: manual }
    debug: { gdbserver: PORT }
)";

TEST(Debugger, ACrashOfAModuleUnderTheDebuggerIsStillDetected) {
  const auto gdb_program = find_gdb();
  if (!gdb_program) GTEST_SKIP() << kSkip;
  const int port = free_loopback_port();
  ASSERT_GT(port, 0);
  BootedSystem sys("debugger_crash", with_port(kCrashing, port));
  // gdb stops the module at the signal; the second continue delivers it and the module dies.
  test::Process gdb(
      gdb_batch(*gdb_program, port, {"continue", "echo oscar-test: stopped\\n", "continue"}),
      test::temp_path("debugger_crash_gdb") + ".log");
  auto s = sys.running();
  const long pid = entry(s, "crashing")->state().pid();
  ASSERT_GT(pid, 0);
  ASSERT_EQ(kill(static_cast<pid_t>(pid), SIGSEGV), 0);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "crashing")->status() == "failed" && st.state() == "suspended";
  });
  const auto* crashing = entry(s, "crashing");
  EXPECT_EQ(crashing->status(), "failed") << "gdb output:\n" << gdb.output();
  EXPECT_THAT(crashing->last_failure(), HasSubstr("SIGSEGV"));
  EXPECT_EQ(s.state(), "suspended");
  EXPECT_TRUE(eventually([&] { return !test::alive(pid); }, 10s)) << "the module process is left";
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
}

}  // namespace
}  // namespace oscar
