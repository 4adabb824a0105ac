// oscar boot's life cycle with real processes on loopback: a busy domain is refused, `oscar
// shutdown` and Ctrl-C (during boot too) end boot, a second Ctrl-C aborts, a killed boot still
// stops the system in order, an operator's restart is no failure, a command's transition shows
// in the system state at once, and the tools find the system booted on this machine without
// flags.
#include <signal.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "oscar/registry/running_systems.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::entry;
using ::testing::HasSubstr;

constexpr const char* kTwoSources = R"(
system: NAME
lease: 1s
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
    restart: { policy: auto, max: 1, backoff: 50ms }
  - name: sink
    kernels: [ { type: bench_sink, name: sink, params: { type: Bool }, inputs: { in: src/out } } ]
    mode: single_step
)";

std::string two_sources(const std::string& name) {
  std::string yaml = kTwoSources;
  yaml.replace(yaml.find("NAME"), 4, name);
  return yaml;
}

// Sets an environment variable for the test's children while it lives.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// A second boot of another file on the same domain.
std::optional<int> boot_again(const std::string& name, std::string& output) {
  const auto file = test::temp_path(name) + ".yaml";
  std::ofstream(file) << two_sources(name);
  test::Process boot(
      {test::bin("oscar-boot"), file, "--domain", std::to_string(test::test_domain()), "--log-dir",
       test::temp_path(name) + "_logs"},
      test::temp_path(name) + "_boot.log");
  const auto code = boot.wait(30s);
  output = boot.output();
  return code;
}

std::vector<long> pids(const SystemState& s) {
  std::vector<long> out;
  for (const auto& m : s.modules()) out.push_back(m.pid());
  return out;
}

TEST(Boot, RefusesADomainWhereASystemRunsAndLeavesThatSystemAlone) {
  BootedSystem first("busy", two_sources("busy"));
  const auto before = first.running();
  std::string output;
  // Found by this machine's record of the domain...
  EXPECT_EQ(boot_again("intruder", output), 2) << output;
  EXPECT_THAT(output, HasSubstr(fmt::format("domain {} is in use by the running system busy",
                                            test::test_domain())));
  EXPECT_THAT(output, HasSubstr("--domain"));
  // ...and, where there is no record (booted elsewhere), by discovery.
  {
    ScopedEnv elsewhere("OSCAR_SYSTEMS_DIR", test::temp_path("no_records"));
    EXPECT_EQ(boot_again("intruder2", output), 2) << output;
    EXPECT_THAT(output, HasSubstr("is in use by the system 'busy' (boot pid"));
    // It waits for the other system's registry to show; its modules may show later than that.
    EXPECT_THAT(output, HasSubstr("oscar-registry"));
  }
  EXPECT_TRUE(test::processes_mentioning(test::temp_path("intruder")).empty());
  const auto after = first.running();
  EXPECT_EQ(pids(after), pids(before)) << "the running system's modules were touched";
  for (const auto& m : after.modules()) EXPECT_EQ(m.incarnation(), 1u) << m.name();
  EXPECT_EQ(first.shut_down(), 0) << first.boot_output();
  EXPECT_THAT(first.boot_output(), ::testing::Not(HasSubstr(" error ")))
      << "Ctrl-C's orderly shutdown is no error";
}

// Boot looks for another system for a moment before it starts its registry; on a loaded machine
// that system may answer later. The registry looks on until it would start its first module:
// this one has no monitor, so it looks until it finds the running system.
TEST(Boot, ARegistryLooksForAnotherSystemUntilItStartsItsFirstModule) {
  BootedSystem first("looked_for", two_sources("looked_for"));
  const auto before = first.running();
  const auto file = test::temp_path("late_intruder") + ".yaml";
  std::ofstream(file) << two_sources("late_intruder");
  test::Process registry({test::bin("oscar-registry"), "--system", file, "--domain",
                          std::to_string(test::test_domain())},
                         test::temp_path("late_intruder_registry.log"));
  EXPECT_EQ(registry.wait(30s), 3) << registry.output();
  EXPECT_THAT(registry.output(),
              HasSubstr(fmt::format("domain {} is in use by the system 'looked_for' (boot pid",
                                    test::test_domain())));
  EXPECT_THAT(registry.output(), HasSubstr("oscar-registry"));
  const auto after = first.running();
  EXPECT_EQ(pids(after), pids(before)) << "the running system's modules were touched";
  for (const auto& m : after.modules()) EXPECT_EQ(m.incarnation(), 1u) << m.name();
  EXPECT_EQ(first.shut_down(), 0) << first.boot_output();
}

TEST(Boot, ExitsWhenTheSystemIsShutDownFromAnotherTerminal) {
  BootedSystem sys("shutdown", two_sources("shutdown"));
  const auto s = sys.running();
  test::Process shutdown(
      {test::bin("oscar-shutdown"), "--domain", std::to_string(test::test_domain())},
      test::temp_path("shutdown_cmd.log"));
  EXPECT_EQ(shutdown.wait(20s), 0) << shutdown.output();
  EXPECT_EQ(sys.boot_exit_code(20s), 0) << sys.boot_output();
  EXPECT_THAT(sys.boot_output(), HasSubstr("the system was shut down (oscar shutdown)"));
  EXPECT_THAT(sys.boot_output(), HasSubstr("all processes stopped"));
  EXPECT_THAT(sys.boot_output(), ::testing::Not(HasSubstr(" error ")))
      << "an orderly shutdown is no error";
  for (const auto pid : pids(s)) EXPECT_FALSE(test::alive(pid)) << "module pid " << pid;
  EXPECT_TRUE(test::processes_mentioning(sys.file()).empty()) << "a process of the system is left";
}

// `src` runs on this host; `far`'s monitor never answers (its ssh hangs), so boot cannot finish.
constexpr const char* kUnreachableHost = R"(
system: unreachable
lease: 1s
hosts: { here: { local: true }, far: { ssh: oscar@far.invalid, address: 127.0.0.1 } }
modules:
  - name: src
    host: here
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
  - name: faraway
    host: far
    kernels: [ { type: bench_sink, name: faraway, params: { type: Bool }, inputs: { in: src/out } } ]
    mode: single_step
)";

// An `ssh` first on boot's PATH that passes boot's check of the host (it runs the check here) but
// then connects to nothing and never returns, as to a host that stops answering.
std::string hanging_ssh() {
  const auto dir = test::temp_path("hanging_ssh");
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/ssh") << "#!/bin/sh\nfor last; do :; done\n"
                                 "case \"$last\" in *' --check '*) exec sh -c \"$last\";; esac\n"
                                 "exec sleep 120\n";
  std::filesystem::permissions(dir + "/ssh", std::filesystem::perms::owner_all);
  return dir + ":" + std::getenv("PATH");
}

SystemState src_running_while_booting(BootedSystem& sys) {
  return sys.wait_for([](const SystemState& st) {
    const auto* src = entry(st, "src");
    return st.state() == "booting" && src && src->status() == "running";
  });
}

TEST(Boot, CtrlCDuringBootIsAcknowledgedAtOnceAndStopsWhatHasStarted) {
  ScopedEnv path("PATH", hanging_ssh());
  BootedSystem sys("ctrlc_boot", kUnreachableHost);
  const auto s = src_running_while_booting(sys);
  const long src = entry(s, "src")->pid();
  ASSERT_EQ(kill(sys.boot_pid(), SIGINT), 0);
  EXPECT_EQ(sys.boot_exit_code(10s), 0) << sys.boot_output();
  EXPECT_THAT(sys.boot_output(), HasSubstr("Ctrl-C during boot: stopping what has started"));
  EXPECT_THAT(sys.boot_output(), HasSubstr("all processes stopped"));
  EXPECT_FALSE(test::alive(src)) << "the module that had started was left running";
  EXPECT_TRUE(test::processes_mentioning(sys.file()).empty()) << "a process of the system is left";
}

TEST(Boot, ASecondCtrlCAbortsAShutdownThatHangs) {
  ScopedEnv path("PATH", hanging_ssh());
  BootedSystem sys("ctrlc_twice", kUnreachableHost);
  const auto s = src_running_while_booting(sys);
  const long src = entry(s, "src")->pid();
  // A registry that does not react: the orderly shutdown would wait for it.
  std::vector<long> registry;
  for (const auto pid : test::processes_mentioning(sys.file())) {
    if (test::proc_file(pid, "cmdline").find("oscar-registry") != std::string::npos) {
      registry.push_back(pid);
    }
  }
  ASSERT_EQ(registry.size(), 1u);
  ASSERT_EQ(kill(static_cast<pid_t>(registry[0]), SIGSTOP), 0);
  ASSERT_EQ(kill(sys.boot_pid(), SIGINT), 0);
  std::this_thread::sleep_for(300ms);
  EXPECT_FALSE(sys.boot_exit_code(0ms)) << "boot did not wait for the registry";
  ASSERT_EQ(kill(sys.boot_pid(), SIGINT), 0);
  EXPECT_EQ(sys.boot_exit_code(5s), 130) << sys.boot_output();
  EXPECT_THAT(sys.boot_output(), HasSubstr("aborted: killing every process of the system"));
  for (int i = 0; i < 100 && test::alive(src); ++i) std::this_thread::sleep_for(20ms);
  EXPECT_FALSE(test::alive(src)) << "the module outlived the abort";
  EXPECT_TRUE(test::processes_mentioning(sys.file()).empty()) << "a process of the system is left";
}

// `oscar boot` killed with SIGKILL (or by the OOM killer) cannot stop anything itself: its
// children get SIGTERM from the kernel (PR_SET_PDEATHSIG), so the registry and the monitor stop
// the modules in reverse boot order, cleanly; nothing of the system runs on, and nothing is
// left in /dev/shm.
TEST(BootDies, AKilledBootStopsTheModulesInOrderAndLeavesNoProcess) {
  BootedSystem sys("boot_killed", two_sources("boot_killed"));
  const auto s = sys.running();
  const long src = entry(s, "src")->pid(), sink = entry(s, "sink")->pid();
  ASSERT_EQ(kill(sys.boot_pid(), SIGKILL), 0);
  EXPECT_TRUE(eventually([&] { return test::processes_mentioning(sys.file()).empty(); }, 30s))
      << "processes of the system outlived boot";
  EXPECT_FALSE(test::alive(src));
  EXPECT_FALSE(test::alive(sink));
  // The last of them removed what the others left in /dev/shm, boot's too.
  EXPECT_EQ(sys.leftover_shared_memory(), std::vector<std::string>{});
  std::ifstream in(sys.log_dir() + "/monitor-localhost.log");  // the monitor's output
  const std::string log((std::istreambuf_iterator<char>(in)), {});
  const auto sink_stopped = log.find(fmt::format("sink (pid {}) exited with code 0", sink));
  const auto src_stopped = log.find(fmt::format("src (pid {}) exited with code 0", src));
  ASSERT_NE(sink_stopped, std::string::npos) << "the sink was not stopped cleanly:\n" << log;
  ASSERT_NE(src_stopped, std::string::npos) << "the source was not stopped cleanly:\n" << log;
  EXPECT_LT(sink_stopped, src_stopped) << "not in reverse boot order:\n" << log;
}

TEST(Registry, AnOperatorRestartIsNoFailureAndCountsNothingAgainstTheLimit) {
  BootedSystem sys("operator_restart", two_sources("operator_restart"));
  auto s = sys.running();
  const long old_pid = entry(s, "src")->pid();
  sys.registry().request(REG_RESTART, "src");
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "src")->incarnation() == 2 && st.state() == "running";
  });
  EXPECT_NE(entry(s, "src")->pid(), old_pid);
  EXPECT_EQ(entry(s, "src")->restarts(), 0u);
  EXPECT_EQ(entry(s, "src")->last_failure(), "");
  // The one failure its limit allows still gets a restart.
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "src")->pid()), SIGKILL), 0);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "src")->incarnation() == 3 && st.state() == "running";
  });
  EXPECT_EQ(entry(s, "src")->restarts(), 1u);
  EXPECT_THAT(entry(s, "src")->last_failure(), HasSubstr("killed by signal 9"));
}

TEST(Registry, AKernelThatKeepsFailingRestartsItsModuleLikeACrash) {
  // A camera that is not there: on_activate() throws every cycle; the default policy ends the
  // process after 3 failures in a row and the registry restarts it.
  BootedSystem sys("kernel_failure", R"(
system: kernel_failure
lease: 1s
modules:
  - name: cam
    kernels: [ { type: framegrabber, name: cam, params: { source: "v4l2:/dev/oscar_no_camera" } } ]
    mode: { continuous: 20ms }
    restart: { policy: auto, max: 1, backoff: 50ms, on_limit: continue }
)");
  const auto s = sys.wait_for([](const SystemState& st) {
    const auto* cam = entry(st, "cam");
    return cam && cam->restarts() == 1 && cam->incarnation() == 2 &&
           cam->last_failure().find("failed 3 times in a row") != std::string::npos;
  });
  EXPECT_THAT(entry(s, "cam")->last_failure(),
              HasSubstr("exited with code 3 (last output: oscar-run: module 'cam' stopped: "
                        "kernel 'cam' failed 3 times in a row (on_kernel_error: restart); last: "
                        "on_activate(): framegrabber 'cam'"));
}

TEST(Registry, ACommandsTransitionReachesTheSystemStateAtOnce) {
  BootedSystem sys("transition", two_sources("transition"));
  sys.running();
  // The registry also republishes the whole state once a second; each change must show long
  // before that (three in a row: by chance all three would fall early in that second 1 in 8).
  for (const auto* cycle : {"30ms", "40ms", "50ms"}) {
    const auto reply = sys.configure("src", CMD_SET_CYCLE, {"src", cycle});
    ASSERT_TRUE(reply.ok()) << reply.error();
    const auto cycle_ns = parse_duration(cycle).count();
    const auto seen = sys.registry().wait_for(
        [&](const SystemState& st) {
          const auto* src = entry(st, "src");
          return src && !src->state().kernels().empty() &&
                 src->state().kernels()[0].cycle_ns() == cycle_ns;
        },
        400ms);
    EXPECT_TRUE(seen) << "set_cycle " << cycle << " not in the system state within 400 ms";
  }
}

std::optional<int> ps(std::string& output) {
  test::Process p({test::bin("oscar-ps"), "--json"}, test::temp_path("ps_no_flags.log"));
  const auto code = p.wait(20s);
  output = p.output();
  return code;
}

// A registry that is found but sends no state (hung) is named as such, apart from none at all.
TEST(Tools, PsAndGraphNameARegistryThatSendsNoState) {
  testing::FreeDomain domain;
  DdsParticipant participant(domain.domain(), "test:hung_registry");
  TopicWriter<SystemState, SystemStatePubSubType> silent(participant, topics::system_state());
  for (const std::string tool : {"oscar-ps", "oscar-graph"}) {
    test::Process p({test::bin(tool), "-d", std::to_string(domain.domain()), "--timeout", "1.5"},
                    test::temp_path(tool + "_hung_registry.log"));
    EXPECT_EQ(p.wait(30s), 1) << p.output();
    EXPECT_THAT(p.output(), HasSubstr(fmt::format("{}: the registry on domain {} sent no state "
                                                  "within 3",
                                                  tool == "oscar-ps" ? "oscar ps" : "oscar graph",
                                                  domain.domain())));
  }
}

TEST(Tools, FindTheSystemBootedOnThisMachineWithoutFlagsAndAskWhenThereAreSeveral) {
  ScopedEnv records("OSCAR_SYSTEMS_DIR", test::temp_path("records"));
  unsetenv("OSCAR_DOMAIN");
  std::filesystem::remove_all(test::temp_path("records"));
  std::string output;
  BootedSystem one("found", two_sources("found"));
  one.running();
  ASSERT_EQ(ps(output), 0) << output;
  EXPECT_EQ(nlohmann::json::parse(output)["system"], "found");
  {
    // oscar record finds it too (it defaulted to domain 0).
    const auto file = test::temp_path("found") + ".mcap";
    test::Process record({test::bin("oscar-record"), "--all", "-o", file},
                         test::temp_path("found_record.log"));
    // Under load it may take a while to find the system and its topics.
    ASSERT_TRUE(eventually(
        [&] { return record.output().find("recording oscar/cue/") != std::string::npos; }, 60s))
        << record.output();
    std::this_thread::sleep_for(1s);
    kill(record.pid(), SIGINT);
    EXPECT_EQ(record.wait(20s), 0) << record.output();
    EXPECT_THAT(record.output(), ::testing::ContainsRegex("received [1-9][0-9]*"))
        << record.output();
    std::filesystem::remove(file);
  }
  const testing::FreeDomain other;
  const auto other_domain = std::to_string(other.domain());
  BootedSystem two("found_too", two_sources("found_too"), other.domain());
  for (int i = 0; i < 500 && running_systems().size() < 2; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(ps(output), 2) << output;
  EXPECT_THAT(output, HasSubstr("2 systems are running on this machine; name one with -d DOMAIN"));
  EXPECT_THAT(output, HasSubstr("found (domain " + std::to_string(test::test_domain())));
  EXPECT_THAT(output, HasSubstr("found_too (domain " + other_domain));
}

}  // namespace
}  // namespace oscar
