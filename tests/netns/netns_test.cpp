// Three test hosts in network namespaces (issue 3, test f): modules spread across them, cues
// crossing hosts over UDP between the test addresses; a killed monitor is a lost host whose
// modules are failed; a monitor started again brings them back; a host cut off stops its modules
// and rejoins when healed (with `on_lost: continue` the rest runs on meanwhile); a killed boot
// leaves no process on any host; each host's clock offset is estimated across the network. Root
// only; skipped otherwise.
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "proc.hpp"     // tests/common
#include "process.hpp"  // tests/common
#include "test_hosts.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using nlohmann::json;

class ThreeHosts : public testing::Test {
 protected:
  void SetUp() override {
    if (const auto why = test::TestHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
    hosts_ = std::make_unique<test::TestHosts>(3);
    file_ = test::temp_path("netns_system") + ".yaml";
    std::ofstream(file_) << fmt::format(R"(
system: three
lease: 1s
hosts:
  h1: {{ local: true, address: {} }}
  h2: {{ netns: {}, address: {}{} }}
  h3: {{ netns: {}, address: {} }}
modules:
  - name: src
    host: h1
    kernels: [ {{ type: bench_source, name: src, params: {{ type: LineSeg3DSeq, lines: 100 }} }} ]
    mode: {{ continuous: 20ms }}
  - name: relay
    host: h2
    kernels: [ {{ type: relay, name: relay, params: {{ type: LineSeg3DSeq }}, inputs: {{ in: src/out }} }} ]
    mode: single_step
    restart: {{ policy: auto, max: 5, backoff: 100ms }}
  - name: sink
    host: h3
    kernels: [ {{ type: bench_sink, name: sink, params: {{ type: LineSeg3DSeq }}, inputs: {{ in: relay/out }} }} ]
    mode: single_step
)",
                                        hosts_->address(1), hosts_->netns(2), hosts_->address(2),
                                        h2_options(), hosts_->netns(3), hosts_->address(3));
    log_dir_ = test::temp_path("netns_logs");
    std::filesystem::remove_all(log_dir_);
    auto argv = hosts_->on(1);  // boot and the registry run on h1
    argv.insert(argv.end(), {test::bin("oscar-boot"), file_, "--domain", domain(), "--log-dir",
                             log_dir_, "--timeout", "40"});
    boot_ = std::make_unique<test::Process>(argv, test::temp_path("netns_boot.log"));
  }
  void TearDown() override {
    if (boot_) {
      kill(boot_->pid(), SIGINT);
      boot_->wait(40s);
    }
    boot_.reset();
    hosts_.reset();
  }

  static std::string domain() { return std::to_string(test::test_domain()); }
  // More keys of h2 in the system file (", key: value").
  virtual std::string h2_options() const { return ""; }

  // `oscar ps --json`, run on h1 (the test process itself is on no test host).
  json ps() {
    auto argv = hosts_->on(1);
    argv.insert(argv.end(),
                {test::bin("oscar-ps"), "--system", file_, "--domain", domain(), "--json"});
    test::Process p(argv, test::temp_path("netns_ps.log"));
    if (p.wait(20s) != 0) return json();
    const auto out = p.output();
    return json::parse(out.substr(out.find('{')), nullptr, false);
  }

  json module(const json& s, const std::string& name) {
    for (const auto& m : s["modules"]) {
      if (m["name"] == name) return m;
    }
    return json();
  }

  // Polls `oscar ps` until `pred` holds.
  json until(const std::function<bool(const json&)>& pred, std::chrono::seconds limit = 40s) {
    const auto end = std::chrono::steady_clock::now() + limit;
    json s;
    while (std::chrono::steady_clock::now() < end) {
      s = ps();
      if (s.is_object() && s.contains("modules") && pred(s)) return s;
      std::this_thread::sleep_for(200ms);
    }
    ADD_FAILURE() << "condition not reached; last state: " << s.dump() << "\nboot:\n"
                  << boot_->output();
    return s;
  }

  // The pids of processes of this system whose command line has all of `words`.
  std::vector<long> processes_with(const std::vector<std::string>& words) const {
    std::vector<long> pids;
    for (const long pid : test::listed_pids()) {
      const auto cmd = test::proc_file(pid, "cmdline");
      if (cmd.find(file_) == std::string::npos) continue;
      if (std::all_of(words.begin(), words.end(), [&](const std::string& w) {
            return cmd.find(w + '\0') != std::string::npos;
          })) {
        pids.push_back(pid);
      }
    }
    return pids;
  }

  // The pids of the monitors of `host` (not the `ip netns exec` that started one).
  std::vector<long> monitors_of(const std::string& host) const {
    std::vector<long> pids;
    for (const long pid : test::listed_pids()) {
      const auto cmd = test::proc_file(pid, "cmdline");
      if (cmd.find("oscar-monitor") != std::string::npos && cmd.find(file_) != std::string::npos &&
          cmd.find(host + '\0') != std::string::npos &&
          cmd.find("ip\0netns", 0, 8) == std::string::npos) {
        pids.push_back(pid);
      }
    }
    return pids;
  }

  std::unique_ptr<test::TestHosts> hosts_;
  std::string file_, log_dir_;
  std::unique_ptr<test::Process> boot_;
};

TEST_F(ThreeHosts, CuesCrossHostsALostHostFailsItsModulesAndComesBack) {
  auto s = until([&](const json& st) { return st["state"] == "running"; });
  EXPECT_EQ(module(s, "relay")["host"], "h2");
  // Cues cross from h1 to h2 and on to h3: the relay republishes them.
  s = until([&](const json& st) {
    return module(st, "relay")["kernels"][0]["published"].get<std::uint64_t>() > 20;
  });

  // Kill h2's monitor: the host is lost, its module dies with it and is marked failed.
  const auto monitors = monitors_of("h2");
  ASSERT_EQ(monitors.size(), 1u);
  ASSERT_EQ(kill(static_cast<pid_t>(monitors[0]), SIGKILL), 0);
  // The failure is published as soon as it is seen, the suspension right after.
  s = until([&](const json& st) {
    return !st["hosts_lost"].empty() && st["hosts_lost"][0] == "h2" &&
           module(st, "relay")["last_failure"].get<std::string>().find("host 'h2' lost") !=
               std::string::npos &&
           st["state"] == "suspended";
  });

  // A new monitor on h2: the registry starts the relay there again and the system resumes.
  auto argv = hosts_->on(2);
  argv.insert(argv.end(), {test::bin("oscar-monitor"), "--system", file_, "--host", "h2",
                           "--domain", domain(), "--log-dir", log_dir_ + "/h2"});
  test::Process monitor(argv, test::temp_path("netns_monitor2.log"));
  s = until([&](const json& st) {
    return st["state"] == "running" && st["hosts_lost"].empty() &&
           module(st, "relay")["incarnation"] == 2 && module(st, "relay")["status"] == "running";
  });
  const auto published = module(s, "relay")["kernels"][0]["published"].get<std::uint64_t>();
  until([&](const json& st) {
    return module(st, "relay")["kernels"][0]["published"].get<std::uint64_t>() > published + 10;
  });
}

}  // namespace
}  // namespace oscar

namespace oscar {
namespace {

// A cable pulled: h2 is cut off. The registry on h1 reports h2 lost and its relay failed; on h2
// the monitor, alone, stops the relay after the registry's discovery lease and headless_limit
// instead of letting it run headless. Healed, h2 rejoins and the relay starts again there, once,
// with the configuration the coordinator had given it (stub on).
TEST_F(ThreeHosts, ACutHostStopsItsModulesAndRejoinsWithTheirConfigurationWhenHealed) {
  until([&](const json& st) { return st["state"] == "running"; });
  auto argv = hosts_->on(1);
  argv.insert(argv.end(), {test::bin("oscar-config"), "relay", "stub", "relay", "on", "--as",
                           "coordinator", "--system", file_, "--domain", domain()});
  test::Process stub(argv, test::temp_path("netns_stub.log"));
  ASSERT_EQ(stub.wait(30s), 0) << stub.output();
  auto s = until([&](const json& st) { return module(st, "relay")["kernels"][0]["stub"] == true; });
  const auto relays = processes_with({"--module", "relay"});
  ASSERT_EQ(relays.size(), 1u);

  hosts_->cut(2);
  s = until([&](const json& st) {
    return !st["hosts_lost"].empty() && st["hosts_lost"][0] == "h2" &&
           module(st, "relay")["last_failure"].get<std::string>().find("host 'h2' lost") !=
               std::string::npos &&
           st["state"] == "suspended";
  });
  // Alone, h2's monitor stops the relay: 3 s of discovery lease, then headless_limit (2 s).
  const auto until_stopped = std::chrono::steady_clock::now() + 40s;
  while (std::filesystem::exists("/proc/" + std::to_string(relays[0])) &&
         std::chrono::steady_clock::now() < until_stopped) {
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_FALSE(std::filesystem::exists("/proc/" + std::to_string(relays[0])))
      << "the relay ran on headless on the far side of the split";
  std::ifstream monitor_log(log_dir_ + "/monitor-h2.log");  // boot keeps its output there
  const std::string h2_log((std::istreambuf_iterator<char>(monitor_log)), {});
  EXPECT_THAT(h2_log, ::testing::HasSubstr("(headless_limit): stopping this host's modules"));

  hosts_->heal(2);
  s = until(
      [&](const json& st) {
        return st["state"] == "running" && st["hosts_lost"].empty() &&
               module(st, "relay")["incarnation"] == 2 &&
               module(st, "relay")["status"] == "running";
      },
      60s);
  EXPECT_EQ(module(s, "relay")["kernels"][0]["stub"], true) << "the configuration was lost";
  EXPECT_EQ(processes_with({"--module", "relay"}).size(), 1u) << "two relays after healing";
  const auto published = module(s, "relay")["kernels"][0]["published"].get<std::uint64_t>();
  until([&](const json& st) {
    return module(st, "relay")["kernels"][0]["published"].get<std::uint64_t>() > published + 10;
  });
}

// Each host's clock is estimated over the network (the probes cross the test hosts' bridge):
// h2's monitor, started again with a clock 250 ms ahead (the test hook), is reported so by
// `oscar ps`, while h1 and h3, on the same kernel clock, are reported near 0.
TEST_F(ThreeHosts, EachHostsClockOffsetIsEstimatedAcrossTheNetwork) {
  until([&](const json& st) { return st["state"] == "running"; });
  const auto monitors = monitors_of("h2");
  ASSERT_EQ(monitors.size(), 1u);
  ASSERT_EQ(kill(static_cast<pid_t>(monitors[0]), SIGKILL), 0);
  auto argv = hosts_->on(2);
  argv.insert(argv.end(),
              {"env", "OSCAR_CLOCK_OFFSET_MS=250", test::bin("oscar-monitor"), "--system", file_,
               "--host", "h2", "--domain", domain(), "--log-dir", log_dir_ + "/h2"});
  test::Process monitor(argv, test::temp_path("netns_monitor_skewed.log"));
  const auto offset_ms = [](const json& st, const std::string& host) -> std::optional<double> {
    for (const auto& c : st["clocks"]) {
      if (c["host"] == host && c["samples"].get<int>() >= 5) {
        return c["offset_ns"].get<double>() / 1e6;
      }
    }
    return std::nullopt;
  };
  const auto s = until(
      [&](const json& st) {
        const auto h2 = offset_ms(st, "h2");
        return h2 && std::abs(*h2 - 250) < 25 && offset_ms(st, "h1") && offset_ms(st, "h3");
      },
      60s);
  EXPECT_NEAR(offset_ms(s, "h1").value_or(1e9), 0, 25) << s["clocks"].dump();
  EXPECT_NEAR(offset_ms(s, "h3").value_or(1e9), 0, 25) << s["clocks"].dump();
  for (const auto& c : s["clocks"]) {
    EXPECT_LT(c["uncertainty_ns"].get<double>() / 1e6, 25) << c.dump();
  }
}

// Boot killed with SIGKILL on h1: every host's monitor stops its modules in order (SIGTERM from
// the kernel as boot dies), and no process of the system is left on any host.
TEST_F(ThreeHosts, AKilledBootLeavesNoProcessOnAnyHost) {
  until([&](const json& st) { return st["state"] == "running"; });
  const auto modules = processes_with({"--module"});
  ASSERT_EQ(modules.size(), 3u);
  ASSERT_EQ(kill(boot_->pid(), SIGKILL), 0);
  const auto limit = std::chrono::steady_clock::now() + 30s;
  while (!processes_with({}).empty() && std::chrono::steady_clock::now() < limit) {
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(processes_with({}), std::vector<long>{}) << "processes of the system outlived boot";
  for (const auto* host : {"h2", "h3"}) {
    std::ifstream in(log_dir_ + "/monitor-" + host + ".log");
    const std::string log((std::istreambuf_iterator<char>(in)), {});
    EXPECT_THAT(log, ::testing::HasSubstr("exited with code 0")) << host << ":\n" << log;
    EXPECT_THAT(log, ::testing::HasSubstr("stopped")) << host << ":\n" << log;
  }
  boot_.reset();  // already dead
}

// The same system with `on_lost: continue` on h2: a robot out of range, say.
class ThreeHostsGoingOn : public ThreeHosts {
 protected:
  std::string h2_options() const override { return ", on_lost: continue"; }
};

// h2 cut off: its relay fails as "host 'h2' lost", and the rest of the system runs on without it
// (src keeps publishing) instead of staying suspended until h2 is back; healed, h2's relay starts
// again, once, and the system never stopped.
TEST_F(ThreeHostsGoingOn, TheRestRunsOnWithoutALostHostsModulesAndTheyRejoinWhenHealed) {
  until([&](const json& st) { return st["state"] == "running"; });
  hosts_->cut(2);
  // Whichever lapses first, h2's monitor (the system never stops) or the relay's heartbeat (the
  // system is suspended, then resumed once the monitor lapses too), the status says so. (A
  // status between the relay's failure and that message is published too: the failure first.)
  auto s = until(
      [&](const json& st) {
        return !st["hosts_lost"].empty() && st["hosts_lost"][0] == "h2" &&
               module(st, "relay")["last_failure"].get<std::string>().find("host 'h2' lost") !=
                   std::string::npos &&
               st["state"] == "running" &&
               st["message"].get<std::string>().find(
                   "without the modules of lost host 'h2' (on_lost: continue)") !=
                   std::string::npos;
      },
      60s);
  const auto published = module(s, "src")["kernels"][0]["published"].get<std::uint64_t>();
  s = until([&](const json& st) {
    return module(st, "src")["kernels"][0]["published"].get<std::uint64_t>() > published + 20;
  });
  EXPECT_EQ(s["hosts_lost"].size(), 1u) << "src ran on only once h2 was back: " << s.dump();
  EXPECT_EQ(s["state"], "running");

  hosts_->heal(2);
  s = until(
      [&](const json& st) {
        return st["state"] == "running" && st["hosts_lost"].empty() &&
               module(st, "relay")["incarnation"] == 2 &&
               module(st, "relay")["status"] == "running";
      },
      60s);
  EXPECT_EQ(processes_with({"--module", "relay"}).size(), 1u) << "two relays after healing";
  s = until([&](const json& st) { return st["message"] == "all modules running again"; });
  const auto relayed = module(s, "relay")["kernels"][0]["published"].get<std::uint64_t>();
  until([&](const json& st) {
    return module(st, "relay")["kernels"][0]["published"].get<std::uint64_t>() > relayed + 10;
  });
}

}  // namespace
}  // namespace oscar
