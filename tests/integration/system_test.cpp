// Registry, monitors and boot with real processes on loopback (issue 3, tests a-e and g).
#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/module.hpp"
#include "test_kernels.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::entry;
using ::testing::HasSubstr;

// Five modules, one of them multi-core (three kernels in one process).
constexpr const char* kFiveModules = R"(
system: five
lease: 1s
modules:
  - name: lines
    kernels: [ { type: bench_source, name: lines, params: { type: LineSeg3DSeq, lines: 10 } } ]
    mode: { continuous: 50ms }
  - name: camera
    kernels: [ { type: bench_source, name: camera, params: { type: GvImage } } ]
    mode: { continuous: 100ms }
  - name: lines_view
    kernels:
      - { type: relay, name: lines_relay, params: { type: LineSeg3DSeq }, inputs: { in: lines/out } }
      - { type: bench_sink, name: lines_sink, params: { type: LineSeg3DSeq }, inputs: { in: lines_relay/out } }
    mode: single_step
  - name: image_view
    kernels: [ { type: bench_sink, name: image_sink, params: { type: GvImage }, inputs: { in: camera/out } } ]
    mode: single_step
  - name: fusion
    kernels:
      - { type: bench_source, name: signal, params: { type: Bool } }
      - { type: relay, name: signal_relay, params: { type: Bool }, inputs: { in: signal/out } }
      - { type: bench_sink, name: signal_sink, params: { type: Bool }, inputs: { in: signal_relay/out } }
    mode: { continuous: 20ms }
)";

TEST(Boot, BootsFiveModulesLetsCuesFlowAndShutsDownLeavingNoProcess) {
  BootedSystem sys("five", kFiveModules);
  auto s = sys.running();
  ASSERT_EQ(s.modules().size(), 5u);
  std::vector<long> pids;
  for (const auto& m : s.modules()) {
    EXPECT_EQ(m.status(), "running") << m.name();
    EXPECT_GT(m.pid(), 0) << m.name();
    EXPECT_EQ(m.incarnation(), 1u);
    pids.push_back(m.pid());
  }
  EXPECT_EQ(entry(s, "fusion")->state().kernels().size(), 3u);
  // Cues flow: every consumer's kernels ran on data, and the registry sees the sources' rates.
  s = sys.wait_for([](const SystemState& st) {
    const auto* view = entry(st, "lines_view");
    const auto* fusion = entry(st, "fusion");
    return view && fusion && view->state().kernels().size() == 2 &&
           view->state().kernels()[1].cycles() > 5 && fusion->cues_per_s() > 10 &&
           entry(st, "image_view")->state().kernels()[0].cycles() > 2 &&
           entry(st, "camera")->cues_per_s() > 0;
  });
  EXPECT_EQ(sys.shut_down(), 0) << sys.boot_output();
  EXPECT_THAT(sys.boot_output(), HasSubstr("all processes stopped"));
  for (const auto pid : pids) EXPECT_FALSE(test::alive(pid)) << "module pid " << pid << " left";
  EXPECT_TRUE(test::processes_mentioning(sys.file()).empty()) << "a process of the system is left";
}

// One source watched by this test process; a sink in another module; a spare source.
constexpr const char* kRestartable = R"(
system: restart
lease: 1s
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
    restart: { policy: auto, max: 3, backoff: 50ms }
  - name: alt
    kernels: [ { type: bench_source, name: alt, params: { type: Bool } } ]
    mode: { continuous: 20ms }
  - name: sink
    kernels: [ { type: bench_sink, name: sink, params: { type: Bool }, inputs: { in: src/out } } ]
    mode: single_step
    restart: { policy: auto, max: 3, backoff: 50ms }
)";

// A consumer started with or before its producer waits in connect_input for the producer's
// writer (up to 2 s per input): the registry launches producers first, whatever the file's order.
TEST(Boot, AConsumerListedBeforeItsProducerIsLaunchedAfterIt) {
  BootedSystem sys("consumer_first", R"(
system: consumer_first
modules:
  - name: sink
    kernels: [ { type: bench_sink, name: sink, params: { type: Bool }, inputs: { in: src/out } } ]
    mode: single_step
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
)");
  sys.running();
  std::ifstream in(sys.log_dir() + "/registry.log");
  const std::string log((std::istreambuf_iterator<char>(in)), {});
  const auto src = log.find("starting 'src'"), sink = log.find("starting 'sink'");
  ASSERT_NE(src, std::string::npos) << log;
  ASSERT_NE(sink, std::string::npos) << log;
  EXPECT_LT(src, sink) << "the sink was launched before its producer:\n" << log;
}

TEST(Registry, KillNineRestartsTheModuleWithItsConfigurationAndWiring) {
  BootedSystem sys("kill9", kRestartable);
  auto s = sys.running();
  // The coordinator changes the sink's wiring and a parameter; both must survive a restart.
  ASSERT_TRUE(sys.configure("sink", CMD_REWIRE, {"sink", "in", "alt/out"}).ok());
  ASSERT_TRUE(sys.configure("sink", CMD_SET_PARAM, {"sink", "log_every", "700ms"}).ok());
  s = sys.wait_for([](const SystemState& st) {
    const auto* k = test::kernel_state(*entry(st, "sink"), "sink");
    return k && k->params().find("700ms") != std::string::npos;
  });
  const long old_pid = entry(s, "sink")->pid();
  ASSERT_EQ(kill(static_cast<pid_t>(old_pid), SIGKILL), 0);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "sink")->incarnation() == 2 && entry(st, "sink")->status() == "running" &&
           st.state() == "running";
  });
  const auto* sink = entry(s, "sink");
  EXPECT_EQ(sink->restarts(), 1u);
  EXPECT_THAT(sink->last_failure(), HasSubstr("killed by signal 9"));
  EXPECT_NE(sink->pid(), old_pid);
  s = sys.wait_for([](const SystemState& st) {
    const auto* k = test::kernel_state(*entry(st, "sink"), "sink");
    return k && !k->inputs().empty() && k->inputs()[0] == "in=alt/out" &&
           k->params().find("700ms") != std::string::npos &&
           !entry(st, "sink")->state().suspended();
  });
}

// A module whose shared-memory port file another process removed (systemd-logind's RemoveIPC,
// an rm) goes on listening where no new sender looks: it ends, saying why, and its registry
// starts it again, and a command from a sender new to it is answered.
TEST(Registry, AModuleWhosePortFileWasRemovedEndsAndIsStartedAgain) {
  BootedSystem sys("port_lost", kRestartable);
  auto s = sys.running();
  const auto old_pid = static_cast<std::uint32_t>(entry(s, "sink")->pid());
  // Its port carries its pid (2^24 + pid * 16 + n); the module's participant is its only one.
  std::vector<std::filesystem::path> ports;
  for (std::uint32_t n = 0; n < 16; ++n) {
    const auto port = std::filesystem::path(
        fmt::format("/dev/shm/fastrtps_port{}", (1u << 24) + old_pid * 16 + n));
    if (std::filesystem::exists(port)) ports.push_back(port);
  }
  ASSERT_EQ(ports.size(), 1u);
  std::filesystem::remove(ports.front());
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "sink")->incarnation() == 2 && entry(st, "sink")->status() == "running" &&
           st.state() == "running";
  });
  EXPECT_NE(entry(s, "sink")->pid(), old_pid);
  std::ifstream log(sys.log_dir() + "/localhost/sink.log");
  const std::string said(std::istreambuf_iterator<char>(log), {});
  EXPECT_THAT(said, HasSubstr(fmt::format("stopping the module: its shared-memory port {} was "
                                          "removed or replaced by another process",
                                          ports.front().string())))
      << said;
  const auto reply = sys.configure("sink", CMD_SET_PARAM, {"sink", "log_every", "700ms"});
  EXPECT_TRUE(reply.ok()) << reply.error();
}

TEST(Registry, ARestartedSourceNeitherRepeatsNorCorruptsItsCues) {
  BootedSystem sys("seq", kRestartable);
  auto s = sys.running();
  // The coordinator sets the source's cycle; the restart must give it back.
  ASSERT_TRUE(sys.configure("src", CMD_SET_CYCLE, {"src", "10ms"}).ok());
  // Watch src/out from this process.
  auto watcher = std::make_unique<Module>(ModuleSpec::from_yaml(YAML::Load(R"(
name: watcher
mode: single_step
kernels: [ { type: test_collect, name: watch, inputs: { in: src/out } } ]
)"),
                                                                "test"),
                                          plugin_search_path());
  watcher->start(test::test_domain());
  auto& collected = dynamic_cast<test::Collect&>(watcher->kernel("watch").kernel());
  std::this_thread::sleep_for(500ms);
  const auto killed_at = wall_now();
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "src")->pid()), SIGKILL), 0);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "src")->incarnation() == 2 && st.state() == "running";
  });
  // The watcher, not part of the system, takes its time to discover the new writer (seconds
  // under a sanitizer on a loaded machine): wait for cues of the new incarnation.
  const auto cues_after_kill = [&] {
    const auto seen = collected.seen();
    return std::count_if(seen.begin(), seen.end(), [&](const auto& cue) {
      return cue->header().stamps().front() > static_cast<unsigned long long>(killed_at);
    });
  };
  for (int i = 0; i < 300 && cues_after_kill() <= 20; ++i) std::this_thread::sleep_for(100ms);
  watcher->stop();
  const auto cues = collected.seen();
  ASSERT_GT(cues.size(), 20u);
  std::size_t after_kill = 0;
  unsigned long long gap_from = 0, gap_to = 0;
  const auto at = [](const auto& cue) { return cue->header().stamps().front(); };
  const auto killed = static_cast<unsigned long long>(killed_at);
  for (std::size_t i = 1; i < cues.size(); ++i) {
    const auto& h = cues[i]->header();
    ASSERT_GT(h.seq(), cues[i - 1]->header().seq()) << "a sequence number came twice or went back";
    EXPECT_EQ(h.source(), "src/out");
    EXPECT_EQ(h.stamps().size(), 1u);
    if (at(cues[i]) > killed && at(cues[i - 1]) <= killed) {
      gap_from = at(cues[i - 1]);
      gap_to = at(cues[i]);
      // The numbers skipped are those of the outage at the 10 ms cycle set above (the watcher,
      // not part of the system, also misses cues until it has discovered the new writer; with a
      // 20 ms bound, one run in seven saw 24 skipped in a 380 ms gap).
      const auto skipped = h.seq() - cues[i - 1]->header().seq() - 1;
      EXPECT_LE(skipped, (gap_to - gap_from) / 10'000'000 + 1)
          << "numbering continues across the restart";
    }
    if (at(cues[i]) > killed) ++after_kill;
  }
  EXPECT_GT(after_kill, 10u);
  // How long the restart takes is `oscar bench boot`'s to measure (restart_ms_p50); the gap seen
  // here also holds the watcher's discovery of the new writer.
  const auto outage_ms = (gap_to - gap_from) / 1'000'000;
  EXPECT_GT(outage_ms, 0u);
  std::cout << "cues of src/out: a gap of " << outage_ms << " ms across the restart\n";
  s = sys.wait_for([](const SystemState& st) {  // the coordinator's cycle was re-applied
    const auto* k = test::kernel_state(*entry(st, "src"), "src");
    return k && k->cycle_ns() == 10'000'000;
  });
  EXPECT_EQ(entry(s, "src")->restarts(), 1u);
}

TEST(Registry, AHungModuleIsDetectedByItsHeartbeatAndRestarted) {
  BootedSystem sys("hang", kRestartable);
  auto s = sys.running();
  const long pid = entry(s, "src")->pid();
  ASSERT_EQ(kill(static_cast<pid_t>(pid), SIGSTOP), 0);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "src")->last_failure().find("heartbeat lost") != std::string::npos;
  });
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "src")->incarnation() == 2 && st.state() == "running";
  });
  EXPECT_NE(entry(s, "src")->pid(), pid);
  for (int i = 0; i < 200 && test::alive(pid); ++i) std::this_thread::sleep_for(10ms);
  EXPECT_FALSE(test::alive(pid)) << "the hung process was killed";
}

constexpr const char* kLimited = R"(
system: limited
lease: 1s
modules:
  - name: flaky
    kernels: [ { type: bench_source, name: flaky, params: { type: Bool } } ]
    mode: { continuous: 20ms }
    restart: { policy: auto, max: 1, backoff: 10ms, on_limit: ON_LIMIT }
  - name: steady
    kernels: [ { type: bench_source, name: steady, params: { type: Bool } } ]
    mode: { continuous: 20ms }
)";

std::string limited(const std::string& on_limit) {
  std::string yaml = kLimited;
  yaml.replace(yaml.find("ON_LIMIT"), 8, on_limit);
  return yaml;
}

void kill_twice(BootedSystem& sys) {
  auto s = sys.running();
  kill(static_cast<pid_t>(entry(s, "flaky")->pid()), SIGKILL);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "flaky")->incarnation() == 2 && st.state() == "running";
  });
  kill(static_cast<pid_t>(entry(s, "flaky")->pid()), SIGKILL);
}

TEST(Registry, AtTheRestartLimitTheModuleIsGivenUpAndTheRestContinuesIfThePolicySaysSo) {
  BootedSystem sys("limit_continue", limited("continue"));
  kill_twice(sys);
  const auto s = sys.wait_for([](const SystemState& st) {
    return entry(st, "flaky")->last_failure().find("restart limit 1 reached") !=
               std::string::npos &&
           st.state() == "running";
  });
  EXPECT_EQ(entry(s, "flaky")->status(), "failed");
  sys.wait_for([](const SystemState& st) { return !entry(st, "steady")->state().suspended(); });
}

TEST(Registry, AtTheRestartLimitTheSystemStaysSuspendedByDefault) {
  BootedSystem sys("limit_suspend", limited("suspend"));
  kill_twice(sys);
  auto s = sys.wait_for([](const SystemState& st) {
    return entry(st, "flaky")->status() == "failed" && st.state() == "suspended";
  });
  EXPECT_THAT(s.message(), HasSubstr("restart limit 1 reached"));
  s = sys.wait_for([](const SystemState& st) { return entry(st, "steady")->state().suspended(); });
  // The operator restarts it by hand: the system runs again.
  sys.registry().request(REG_RESTART, "flaky");
  sys.wait_for([](const SystemState& st) {
    return entry(st, "flaky")->incarnation() == 3 && st.state() == "running";
  });
}

// A request is a sample anyone on the domain may write: a kind outside the enum and over-long
// names are refused with the rule, and nothing is restarted.
TEST(Registry, RequestsOfAnUnknownKindOrWithOverlongNamesAreRefused) {
  BootedSystem sys("bad_requests", kFiveModules);
  const auto before = sys.running();
  const auto refusal = [&](const std::string& sender, int kind, const std::string& module) {
    RegistryClient client(sys.participant(), sender);
    try {
      client.request(static_cast<RegistryRequestKind>(kind), module);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(refusal("operator", 7, "camera"),
              HasSubstr("refused: request kind 7 is neither restart (0) nor shutdown (1)"));
  EXPECT_THAT(refusal(std::string(100000, 's'), REG_RESTART, "camera"),
              HasSubstr("refused: a request's sender (100000 bytes) and module name (6 bytes) "
                        "may have at most 256 characters"));
  EXPECT_THAT(refusal("operator", REG_RESTART, std::string(300, 'm')),
              HasSubstr("module name (300 bytes)"));
  const auto after = sys.registry().latest();
  ASSERT_TRUE(after);
  EXPECT_EQ(after->state(), "running");
  const auto *now = entry(*after, "camera"), *then = entry(before, "camera");
  ASSERT_TRUE(now && then) << "the registry does not list module 'camera'";
  EXPECT_EQ(now->incarnation(), then->incarnation());
}

// Restart limit 1 within 6 s: a failure after the window is restarted again; the count was
// never reset, so the second failure gave the module up however long after the first it came.
TEST(Registry, ARestartOlderThanTheWindowNoLongerCountsAgainstTheLimit) {
  std::string yaml = limited("suspend");
  yaml.replace(yaml.find("max: 1,"), 7, "max: 1, window: 6s,");
  BootedSystem sys("limit_window", yaml);
  auto s = sys.running();
  kill(static_cast<pid_t>(entry(s, "flaky")->pid()), SIGKILL);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "flaky")->incarnation() == 2 && st.state() == "running";
  });
  std::this_thread::sleep_for(std::chrono::seconds(7));  // the first restart leaves the window
  kill(static_cast<pid_t>(entry(s, "flaky")->pid()), SIGKILL);
  s = sys.wait_for([](const SystemState& st) {
    const auto* flaky = entry(st, "flaky");
    // "failed" is published before "restarting": only the limit's text says given up.
    return (flaky->incarnation() == 3 && st.state() == "running") ||
           flaky->last_failure().find("restart limit") != std::string::npos;
  });
  EXPECT_EQ(entry(s, "flaky")->incarnation(), 3u) << entry(s, "flaky")->last_failure();
  EXPECT_EQ(entry(s, "flaky")->restarts(), 2u);
  // A third failure within 6 s of the second restart is over the limit.
  kill(static_cast<pid_t>(entry(s, "flaky")->pid()), SIGKILL);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "flaky")->last_failure().find("restart limit") != std::string::npos;
  });
  EXPECT_EQ(entry(s, "flaky")->status(), "failed");
  EXPECT_THAT(entry(s, "flaky")->last_failure(), HasSubstr("restart limit 1 reached within 6s"));
}

TEST(Registry, ReplacePolicyStartsTheStandbyModuleAndRewiresItsConsumers) {
  BootedSystem sys("replace", R"(
system: replace
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
  EXPECT_EQ(entry(s, "cam_spare")->status(), "standby");
  kill(static_cast<pid_t>(entry(s, "cam")->pid()), SIGKILL);
  s = sys.wait_for([](const SystemState& st) {
    return entry(st, "cam")->status() == "replaced" &&
           entry(st, "cam_spare")->status() == "running" && st.state() == "running";
  });
  s = sys.wait_for([](const SystemState& st) {
    const auto* k = test::kernel_state(*entry(st, "view"), "view");
    return k && !k->inputs().empty() && k->inputs()[0] == "in=cam2/out" && k->cycles() > 0;
  });
  const auto cycles = test::kernel_state(*entry(s, "view"), "view")->cycles();
  sys.wait_for([cycles](const SystemState& st) {
    const auto* k = test::kernel_state(*entry(st, "view"), "view");
    return k && k->cycles() > cycles + 5;
  });
}

struct BadSystem {
  std::string name, yaml, message;
};

// A robot and the start of a `coordinator: swarm:` section; the section's keys follow at line 4.
constexpr const char* kFleet =
    "modules: [ { name: fleet, kernels: [ { type: robot_sim, name: r1 } ] } ]\n"
    "coordinator:\n"
    "  swarm:\n";

class BootRefuses : public ::testing::TestWithParam<BadSystem> {};

TEST_P(BootRefuses, BadSystemFilesWithAClearErrorAndStartsNothing) {
  const auto& bad = GetParam();
  const auto file = test::temp_path("bad_" + bad.name) + ".yaml";
  std::ofstream(file) << bad.yaml;
  const auto log_dir = test::temp_path("bad_" + bad.name) + "_logs";
  std::filesystem::remove_all(log_dir);
  test::Process boot({test::bin("oscar-boot"), file, "--log-dir", log_dir, "--domain",
                      std::to_string(test::test_domain())},
                     test::temp_path("bad_boot.log"));
  EXPECT_EQ(boot.wait(30s), 2);
  EXPECT_THAT(boot.output(), HasSubstr(bad.message));
  EXPECT_FALSE(std::filesystem::exists(log_dir)) << "something was started";
  EXPECT_TRUE(test::processes_mentioning(file).empty());
}

// `oscar boot --check` says no to what boot would refuse, the live swarm's section included.
TEST(Boot, CheckRefusesABadSwarmSectionAsBootWould) {
  const auto file = test::temp_path("bad_swarm_check") + ".yaml";
  std::ofstream(file) << kFleet << "    lost_after_ms: soon\n";
  test::Process check({test::bin("oscar-boot"), file, "--check"},
                      test::temp_path("bad_swarm_check.log"));
  EXPECT_EQ(check.wait(30s), 2);
  EXPECT_THAT(check.output(),
              HasSubstr("oscar boot: " + file + ":4: swarm.lost_after_ms: expected a number"));
  EXPECT_THAT(check.output(), ::testing::Not(HasSubstr(": ok")));
  std::filesystem::remove(file);
}

INSTANTIATE_TEST_SUITE_P(
    Registry, BootRefuses,
    ::testing::Values(
        BadSystem{"malformed", "system: x\nmodules:\n  - name: [a\n", ":4:1: malformed YAML"},
        BadSystem{"unknown_type",
                  "modules: [ { name: m, kernels: [ { type: warp_drive, name: k } ] } ]",
                  "warp_drive"},
        BadSystem{"unknown_host",
                  "hosts: { a: { local: true } }\nmodules: [ { name: m, host: b, kernels: [ { "
                  "type: relay } ] } ]",
                  "unknown host 'b'"},
        BadSystem{"duplicate",
                  "modules: [ { name: m, kernels: [ { type: relay, name: a } ] }, { name: m, "
                  "kernels: [ { type: relay, name: b } ] } ]",
                  "duplicate module name 'm'"},
        BadSystem{"cyclic",
                  "modules:\n - { name: a, kernels: [ { type: relay, name: ka } ], restart: { "
                  "replace: b } }\n - { name: b, standby: true, kernels: [ { type: relay, name: "
                  "kb } ], restart: { replace: c } }\n - { name: c, standby: true, kernels: [ { "
                  "type: relay, name: kc } ], restart: { replace: b } }\n",
                  "cyclic replace chain: a -> b -> c -> b"},
        BadSystem{"missing_netns",
                  "hosts: { a: { local: true }, b: { netns: oscar_no_such_ns } }\nmodules: [ { "
                  "name: m, host: b, kernels: [ { type: relay } ] } ]",
                  "network namespace 'oscar_no_such_ns' does not exist"},
        BadSystem{"service_of_no_module",
                  "modules: [ { name: m, kernels: [ { type: relay } ] } ]\n"
                  "services: { Camera: { provided_by: [cam] } }\ncoordinator: {}\n",
                  ":2: service 'Camera'.provided_by: no module 'cam' in the system"},
        BadSystem{"unknown_applet_type",
                  "modules: [ { name: m, kernels: [ { type: relay } ] } ]\n"
                  "services: { S: { provided_by: [m] } }\ncoordinator:\n  applets:\n"
                  "    - { type: warp_applet, name: a }\n",
                  ":5: applet 'a': unknown applet type 'warp_applet'"},
        // The live swarm's section: the coordinator reads it, boot checks it as the coordinator
        // will (".yaml:LINE": the line of the fault right after the file's name).
        BadSystem{"swarm_unknown_key", std::string(kFleet) + "    ack_timout_ms: 300\n",
                  ".yaml:4: coordinator.swarm: unknown key 'ack_timout_ms'"},
        BadSystem{"swarm_robot_of_no_kernel", std::string(kFleet) + "    robots: [r1, nobody]\n",
                  ".yaml:4: swarm.robots: no kernel named 'nobody' in the system"},
        BadSystem{"swarm_bow_tie_obstacle",
                  std::string(kFleet) +
                      "    world:\n      static:\n        - [[0, 0], [1, 1], [0, 1], [1, 0]]\n",
                  ".yaml:6:11: world.static[0]: polygon is self-intersecting"}),
    [](const ::testing::TestParamInfo<BadSystem>& param) { return param.param.name; });

}  // namespace
}  // namespace oscar
