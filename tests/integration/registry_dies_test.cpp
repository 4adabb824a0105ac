// The registry dies while the system runs (issue 19): boot starts it again with --recover and
// the new one adopts the running modules instead of starting them twice.
#include <signal.h>

#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <oscar/registryPubSubTypes.h>

#include "booted_system.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::entry;
using ::testing::HasSubstr;

constexpr const char* kThreeModules = R"(
system: regdies
lease: 1s
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
    restart: { policy: auto, max: 3, backoff: 50ms }
  - name: relay
    kernels: [ { type: relay, name: relay, params: { type: Bool }, inputs: { in: src/out } } ]
    mode: single_step
    restart: { policy: auto, max: 3, backoff: 50ms }
  - name: sink
    kernels: [ { type: bench_sink, name: sink, params: { type: Bool }, inputs: { in: relay/out } } ]
    mode: single_step
    restart: { policy: auto, max: 3, backoff: 50ms }
)";

std::vector<std::string> command_line(long pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline");
  std::vector<std::string> args;
  for (std::string arg; std::getline(in, arg, '\0');) args.push_back(arg);
  return args;
}

// The live processes of the system in `file` whose command line satisfies `match`.
std::vector<long> processes_of(const std::string& file,
                               const std::function<bool(const std::vector<std::string>&)>& match) {
  std::vector<long> out;
  for (const long pid : test::processes_mentioning(file)) {
    if (match(command_line(pid))) out.push_back(pid);
  }
  return out;
}

// Every process running module `module` (oscar-run FILE --module M ...).
std::vector<long> module_processes(const std::string& file, const std::string& module) {
  return processes_of(file, [&](const auto& args) {
    for (std::size_t i = 0; i + 1 < args.size(); ++i) {
      if (args[i] == "--module" && args[i + 1] == module) return true;
    }
    return false;
  });
}

long registry_pid(const std::string& file) {
  const auto pids = processes_of(file, [](const auto& args) {
    return !args.empty() && std::filesystem::path(args[0]).filename() == "oscar-registry";
  });
  return pids.size() == 1 ? pids.front() : 0;
}

bool recovered(const SystemState& s) {
  return s.state() == "running" && s.message().find("registry recovered") != std::string::npos;
}

// Boot's output, once it says `text` (it is printed a moment after it happens).
std::string boot_output_saying(BootedSystem& sys, const std::string& text) {
  for (int i = 0; i < 100 && sys.boot_output().find(text) == std::string::npos; ++i) {
    std::this_thread::sleep_for(100ms);
  }
  return sys.boot_output();
}

TEST(RegistryDies, ARestartedRegistryAdoptsTheRunningModulesWithoutDuplicates) {
  BootedSystem sys("regdies_adopt", kThreeModules);
  auto s = sys.running();
  std::map<std::string, long> pids;
  for (const auto& m : s.modules()) {
    pids[m.name()] = m.pid();
    ASSERT_EQ(module_processes(sys.file(), m.name()), std::vector<long>{m.pid()}) << m.name();
  }
  const long old_registry = registry_pid(sys.file());
  ASSERT_GT(old_registry, 0) << "no single oscar-registry process of " << sys.file();
  ASSERT_EQ(kill(static_cast<pid_t>(old_registry), SIGKILL), 0);

  s = sys.wait_for(recovered, 60s);
  EXPECT_THAT(s.message(), HasSubstr("3 modules running were adopted, 0 started"));
  const long new_registry = registry_pid(sys.file());
  EXPECT_GT(new_registry, 0);
  EXPECT_NE(new_registry, old_registry);
  for (const auto& m : s.modules()) {
    EXPECT_EQ(m.status(), "running") << m.name();
    EXPECT_EQ(m.incarnation(), 1u) << m.name();
    EXPECT_EQ(m.pid(), pids[m.name()]) << m.name() << " was started again";
    EXPECT_EQ(module_processes(sys.file(), m.name()), std::vector<long>{pids[m.name()]})
        << m.name() << " runs more than once, or not as before";
  }
  // Cues still flow from the source through the relay to the sink.
  const auto* sink = test::kernel_state(*entry(s, "sink"), "sink");
  ASSERT_NE(sink, nullptr);
  const auto cycles = sink->cycles();
  sys.wait_for([&](const SystemState& st) {
    const auto* k = test::kernel_state(*entry(st, "sink"), "sink");
    return recovered(st) && k && k->cycles() > cycles + 10;
  });
  EXPECT_THAT(
      boot_output_saying(sys, "restarting it"),
      HasSubstr("registry died (killed by signal 9 (Killed)): restarting it (1 of 5 in 60 s)"));
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
  for (const auto& [name, pid] : pids) EXPECT_FALSE(test::alive(pid)) << name << " left running";
}

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(RegistryDies, AGarbledJournalIsSaidAndTheRecoveryGoesOnWithoutIt) {
  BootedSystem sys("regdies_garbled", kThreeModules);
  const auto s = sys.running();
  const auto journal = sys.log_dir() + "/registry.journal.yaml";
  ASSERT_THAT(file_text(journal), HasSubstr("oscar_registry_journal")) << journal;
  std::ofstream(journal, std::ios::trunc) << "oscar_registry_journal: 1\nmodules: [ { name: src";
  const long old_registry = registry_pid(sys.file());
  ASSERT_GT(old_registry, 0);
  ASSERT_EQ(kill(static_cast<pid_t>(old_registry), SIGKILL), 0);

  const auto back = sys.wait_for(recovered, 60s);
  EXPECT_THAT(back.message(), HasSubstr("3 modules running were adopted, 0 started"));
  for (const auto& m : back.modules()) EXPECT_EQ(m.pid(), entry(s, m.name())->pid()) << m.name();
  const auto log = file_text(sys.log_dir() + "/registry.log");
  EXPECT_THAT(log, HasSubstr(journal + ": not a registry journal (not YAML"));
  EXPECT_THAT(log, HasSubstr("recovering without it"));
  EXPECT_THAT(file_text(journal), HasSubstr("end: true")) << "the new registry writes it anew";
}

// The sink restarts 3 s after a failure: time enough to kill the registry before it has.
constexpr const char* kSlowRestart = R"(
system: regdies_mid
lease: 1s
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
  - name: sink
    kernels: [ { type: bench_sink, name: sink, params: { type: Bool }, inputs: { in: src/out } } ]
    mode: single_step
    restart: { policy: auto, max: 3, backoff: 3s }
)";

bool sink_has_its_parameter(const SystemState& s) {
  const auto* k = test::kernel_state(*entry(s, "sink"), "sink");
  return k && k->params().find("700ms") != std::string::npos;
}

TEST(RegistryDies, AKilledRegistryMidRestartFinishesTheRestart) {
  BootedSystem sys("regdies_mid", kSlowRestart);
  auto s = sys.running();
  ASSERT_TRUE(sys.configure("sink", CMD_SET_PARAM, {"sink", "log_every", "700ms"}).ok());
  s = sys.wait_for(sink_has_its_parameter);
  const long src_pid = entry(s, "src")->pid();
  const long old_sink = entry(s, "sink")->pid();
  const long old_registry = registry_pid(sys.file());
  ASSERT_GT(old_registry, 0);

  ASSERT_EQ(kill(static_cast<pid_t>(old_sink), SIGKILL), 0);
  s = sys.wait_for(
      [](const SystemState& st) { return entry(st, "sink")->status() == "restarting"; });
  ASSERT_EQ(kill(static_cast<pid_t>(old_registry), SIGKILL), 0);

  s = sys.wait_for(recovered, 60s);
  const auto* sink = entry(s, "sink");
  EXPECT_EQ(sink->incarnation(), 2u) << "restarted once";
  EXPECT_EQ(sink->restarts(), 1u) << "the restart counter continues";
  EXPECT_THAT(sink->last_failure(), HasSubstr("killed by signal 9"));
  EXPECT_NE(sink->pid(), old_sink);
  EXPECT_EQ(module_processes(sys.file(), "sink"), std::vector<long>{sink->pid()});
  EXPECT_EQ(entry(s, "src")->pid(), src_pid) << "the source was adopted, not started again";
  EXPECT_EQ(module_processes(sys.file(), "src"), std::vector<long>{src_pid});
  EXPECT_THAT(s.message(), HasSubstr("1 modules running were adopted, 1 started"));
  // With its configuration, and the system resumed: the sink runs on the source's cues.
  const auto* k = test::kernel_state(*sink, "sink");
  ASSERT_NE(k, nullptr);
  const auto cycles = k->cycles();
  s = sys.wait_for([&](const SystemState& st) {
    const auto* now = test::kernel_state(*entry(st, "sink"), "sink");
    return sink_has_its_parameter(st) && now && now->cycles() > cycles + 10 &&
           !entry(st, "src")->state().suspended();
  });
  EXPECT_EQ(entry(s, "sink")->incarnation(), 2u);
  EXPECT_THAT(boot_output_saying(sys, "restarting it"), HasSubstr("registry died"));
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
}

// A registry whose shared-memory port file another process removed (systemd-logind's RemoveIPC,
// an rm) could no longer be reached by a process that starts later: it ends, leaving the system
// running, and the registry boot starts in its place adopts it and restarts a module killed
// afterwards (whose new process it hears).
TEST(RegistryDies, ARegistryWhosePortFileWasRemovedHandsTheSystemToANewOne) {
  BootedSystem sys("regdies_port", kThreeModules);
  auto s = sys.running();
  std::map<std::string, long> pids;
  for (const auto& m : s.modules()) pids[m.name()] = m.pid();
  const long old_registry = registry_pid(sys.file());
  ASSERT_GT(old_registry, 0) << "no single oscar-registry process of " << sys.file();
  // Its port carries its pid (2^24 + pid * 16 + n); the registry has one participant.
  std::vector<std::filesystem::path> ports;
  for (long n = 0; n < 16; ++n) {
    const auto port = std::filesystem::path(
        fmt::format("/dev/shm/fastrtps_port{}", (1L << 24) + old_registry * 16 + n));
    if (std::filesystem::exists(port)) ports.push_back(port);
  }
  ASSERT_EQ(ports.size(), 1u);
  std::filesystem::remove(ports.front());

  s = sys.wait_for(recovered, 60s);
  EXPECT_THAT(s.message(), HasSubstr("3 modules running were adopted, 0 started"));
  EXPECT_NE(registry_pid(sys.file()), old_registry);
  for (const auto& m : s.modules()) EXPECT_EQ(m.pid(), pids[m.name()]) << m.name();
  EXPECT_THAT(boot_output_saying(sys, "restarting it"),
              HasSubstr("registry died (exited with code 4): restarting it (1 of 5 in 60 s)"));
  EXPECT_THAT(file_text(sys.log_dir() + "/registry.log"),
              HasSubstr(fmt::format("registry: ending and leaving the system running: its "
                                    "shared-memory port {} was removed or replaced",
                                    ports.front().string())));

  ASSERT_EQ(kill(static_cast<pid_t>(pids["sink"]), SIGKILL), 0);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "sink")->incarnation() == 2 && entry(st, "sink")->status() == "running" &&
           st.state() == "running";
  });
  EXPECT_EQ(module_processes(sys.file(), "sink"), std::vector<long>{entry(s, "sink")->pid()});
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
}

TEST(RegistryDies, BootGivesUpAfterFiveDeathsInAMinute) {
  BootedSystem sys("regdies_limit", kSlowRestart);
  const auto s = sys.running();
  const long src_pid = entry(s, "src")->pid();
  std::vector<long> killed;
  for (int death = 1; death <= 6; ++death) {
    long pid = 0;  // the registry boot started after the last death
    for (int i = 0; i < 500 && pid == 0; ++i) {
      pid = registry_pid(sys.file());
      if (!killed.empty() && pid == killed.back()) pid = 0;
      if (pid == 0) std::this_thread::sleep_for(20ms);
    }
    ASSERT_GT(pid, 0) << "no registry after death " << death - 1 << "\n" << sys.boot_output();
    ASSERT_EQ(kill(static_cast<pid_t>(pid), SIGKILL), 0);
    killed.push_back(pid);
  }
  EXPECT_EQ(sys.boot_exit_code(60s), 1) << sys.boot_output();
  const auto out = sys.boot_output();
  EXPECT_THAT(out, HasSubstr("restarting it (5 of 5 in 60 s)"));
  EXPECT_THAT(out, HasSubstr("for the 6th time within 60 s: giving up, stopping the system"));
  EXPECT_THAT(out, HasSubstr("all processes stopped"));
  EXPECT_FALSE(test::alive(src_pid)) << "the modules are stopped";
  EXPECT_TRUE(test::processes_mentioning(sys.file()).empty()) << "a process of the system is left";
}

// A module the registry before had replaced stays replaced; its standby is adopted.
TEST(RegistryDies, AReplacedModuleStaysReplacedAndItsStandbyIsAdopted) {
  BootedSystem sys("regdies_replace", R"(
system: regdies_replace
lease: 1s
modules:
  - name: cam
    kernels: [ { type: bench_source, name: cam, params: { type: Bool } } ]
    mode: { continuous: 20ms }
    restart: { replace: cam_spare }
  - name: cam_spare
    standby: true
    kernels: [ { type: bench_source, name: cam2, params: { type: Bool } } ]
    mode: { continuous: 20ms }
  - name: view
    kernels: [ { type: bench_sink, name: view, params: { type: Bool }, inputs: { in: cam/out } } ]
    mode: single_step
)");
  auto s = sys.running();
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "cam")->pid()), SIGKILL), 0);
  s = sys.wait_for([](const SystemState& st) {
    const auto* k = test::kernel_state(*entry(st, "view"), "view");
    return entry(st, "cam")->status() == "replaced" &&
           entry(st, "cam_spare")->status() == "running" && st.state() == "running" && k &&
           !k->inputs().empty() && k->inputs()[0] == "in=cam2/out";
  });
  const long spare = entry(s, "cam_spare")->pid();
  const long old_registry = registry_pid(sys.file());
  ASSERT_GT(old_registry, 0);
  ASSERT_EQ(kill(static_cast<pid_t>(old_registry), SIGKILL), 0);

  s = sys.wait_for(recovered, 60s);
  EXPECT_THAT(s.message(), HasSubstr("2 modules running were adopted, 0 started"));
  EXPECT_EQ(entry(s, "cam")->status(), "replaced");
  EXPECT_TRUE(module_processes(sys.file(), "cam").empty()) << "the replaced module was started";
  EXPECT_EQ(entry(s, "cam_spare")->pid(), spare);
  EXPECT_EQ(module_processes(sys.file(), "cam_spare"), std::vector<long>{spare});
  const auto cycles = test::kernel_state(*entry(s, "view"), "view")->cycles();
  sys.wait_for([cycles](const SystemState& st) {
    const auto* k = test::kernel_state(*entry(st, "view"), "view");
    return k && k->inputs()[0] == "in=cam2/out" && k->cycles() > cycles + 5;
  });
}

// Defence in depth: whatever a registry asks, a monitor never starts a module twice.
TEST(RegistryDies, AMonitorRefusesToStartAModuleItAlreadyRuns) {
  BootedSystem sys("regdies_refuse", kSlowRestart);
  const auto s = sys.running();
  const auto* src = entry(s, "src");
  const auto monitors = processes_of(sys.file(), [](const auto& args) {
    return !args.empty() && std::filesystem::path(args[0]).filename() == "oscar-monitor";
  });
  ASSERT_EQ(monitors.size(), 1u);
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<ProcessEvent> refused;
  TopicReader<ProcessEvent, ProcessEventPubSubType> events(
      sys.participant(), topics::process_events(), [&](const ProcessEvent& e, const auto&) {
        if (e.module_name() != "src" || e.kind() != PROC_START_FAILED) return;
        std::lock_guard lock(mutex);
        refused = e;
        changed.notify_all();
      });
  // What a registry that lost track of `src` would ask (its writer keeps it for the monitor).
  TopicWriter<LaunchRequest, LaunchRequestPubSubType> launch(sys.participant(), topics::launch());
  LaunchRequest q;
  q.id(static_cast<unsigned long long>(wall_now()));
  q.host(src->host());
  q.monitor_pid(static_cast<std::int32_t>(monitors.front()));
  q.kind(LAUNCH_START);
  q.module_name("src");
  q.incarnation(src->incarnation() + 1);
  launch.write(q);
  {
    std::unique_lock lock(mutex);
    ASSERT_TRUE(changed.wait_for(lock, 30s, [&] { return refused.has_value(); }))
        << "the monitor did not answer the start";
    EXPECT_THAT(refused->detail(), HasSubstr(fmt::format("already running as pid {}", src->pid())));
  }
  EXPECT_EQ(module_processes(sys.file(), "src"), std::vector<long>{src->pid()});
  const auto after = sys.wait_for([](const SystemState& st) { return st.state() == "running"; });
  EXPECT_EQ(entry(after, "src")->pid(), src->pid());
  EXPECT_EQ(entry(after, "src")->incarnation(), src->incarnation());
}

}  // namespace
}  // namespace oscar
