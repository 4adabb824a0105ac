// `zero_copy:` in a system file: each host's monitor keeps the host's RouDi running
// (docs/zero_copy.md, "RouDi per host"). The test process has a mount namespace of its own with
// fresh /dev/shm and /tmp (private_tmp.hpp), so its RouDis meet nobody else's.
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/module_spec.hpp"
#include "oscar/registry/host_check.hpp"
#include "private_tmp.hpp"
#include "proc.hpp"
#include "process.hpp"
#include "zero_copy/mempools.hpp"
#include "zero_copy/roudi.hpp"

namespace oscar {
namespace {

using namespace std::chrono_literals;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;

template <class Condition>
bool eventually(Condition condition, std::chrono::milliseconds timeout = 30s) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(20ms);
  }
  return true;
}

// The iox-roudi processes in this test's mount namespace (tests running beside it have their
// own).
std::vector<long> roudis() {
  std::error_code ec;
  const auto ours = std::filesystem::read_symlink("/proc/self/ns/mnt", ec);
  std::vector<long> out;
  for (const auto pid : test::listed_pids()) {
    if (test::proc_file(pid, "comm") != "iox-roudi\n") continue;
    const auto theirs =
        std::filesystem::read_symlink("/proc/" + std::to_string(pid) + "/ns/mnt", ec);
    if (!ec && theirs == ours) out.push_back(pid);
  }
  return out;
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class HostRoudi : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::kNoPrivateTmp.empty())
      GTEST_SKIP() << "needs a private mount namespace (root): " << test::kNoPrivateTmp;
    ASSERT_FALSE(zero_copy::roudi_running());
    std::ofstream(file_) << fmt::format(R"(system: zc
domain: {}
zero_copy: {{ chunks: 8 }}
modules:
  - name: src
    kernels: [ {{ type: bench_source, name: src }} ]
)",
                                        test::test_domain());
  }
  void TearDown() override {
    if (monitor_) monitor_->stop();
    for (const auto pid : roudis()) ::kill(static_cast<pid_t>(pid), SIGKILL);
  }
  test::Process& start_monitor() {
    monitor_ = std::make_unique<test::Process>(
        std::vector<std::string>{test::bin("oscar-monitor"), "--system", file_, "--host",
                                 "localhost", "--log-dir", log_dir_},
        "/tmp/monitor.log");
    return *monitor_;
  }
  bool monitor_said(const std::string& text) const {
    return monitor_->output().find(text) != std::string::npos;
  }
  test::Process peer(std::vector<std::string> args, const std::string& name) {
    args.insert(args.begin(), test::bin("oscar-zero-copy-peer"));
    return test::Process(std::move(args), "/tmp/" + name + ".log");
  }
  // `count` cues of `type`, 10 ms apart, from one zero-copy peer to another through this host's
  // RouDi: every one arrives; the consumer holds `hold`, the producer `loans` loaned chunks.
  void cues_flow(const std::string& type, const std::string& count, const std::string& hold,
                 const std::string& loans) {
    auto sub = peer({"sub", type, "topic", count, hold}, "sub");
    ASSERT_TRUE(eventually([&] { return sub.output().find("subscribed") != std::string::npos; }))
        << sub.output();
    auto pub = peer({"pub", type, "topic", count, "10", loans, "0", "1"}, "pub");
    EXPECT_EQ(pub.wait(60s), 0) << pub.output();
    EXPECT_EQ(sub.wait(60s), 0) << sub.output();
  }

  const std::string file_ = "/tmp/zc.yaml";
  const std::string log_dir_ = "/tmp/zc-logs";
  std::unique_ptr<test::Process> monitor_;
};

TEST_F(HostRoudi, TheMonitorStartsOneWithThePlainTypesMempoolsAndCuesFlowThroughIt) {
  auto& monitor = start_monitor();
  ASSERT_TRUE(eventually([&] { return monitor_said("RouDi runs"); })) << monitor.output();
  EXPECT_TRUE(zero_copy::roudi_running());
  EXPECT_EQ(roudis().size(), 1u);
  EXPECT_EQ(read(log_dir_ + "/roudi.toml"),
            zero_copy::roudi_config(zero_copy::plain_cue_mempools(8)));
  // Images through the monitor's RouDi: 8 chunks are enough for a producer holding 2 loans and a
  // consumer holding 4 cues.
  cues_flow("PlainGvImage", "20", "4", "2");
}

TEST_F(HostRoudi, StoppingTheMonitorStopsItsRouDiWhichStopsTheProcessesThatJoinedIt) {
  auto& monitor = start_monitor();
  ASSERT_TRUE(eventually([&] { return monitor_said("RouDi runs"); })) << monitor.output();
  auto sub = peer({"sub", "PlainBool", "flag", "1000", "1"}, "sub");  // waits for cues
  ASSERT_TRUE(eventually([&] { return sub.output().find("subscribed") != std::string::npos; }))
      << sub.output();
  ::kill(monitor.pid(), SIGTERM);
  EXPECT_EQ(monitor.wait(20s), 0) << monitor.output();
  EXPECT_THAT(monitor.output(), HasSubstr("stopped RouDi"));
  EXPECT_FALSE(zero_copy::roudi_running());
  EXPECT_TRUE(roudis().empty());
  EXPECT_EQ(sub.wait(10s), 128 + SIGTERM) << sub.output();
  EXPECT_FALSE(std::filesystem::exists("/dev/shm/iceoryx_mgmt"))
      << read(log_dir_ + "/iox-roudi.log");
}

TEST_F(HostRoudi, AKilledRouDiIsStartedAgainAndSaysWhatThatMeansForJoinedProcesses) {
  auto& monitor = start_monitor();
  ASSERT_TRUE(eventually([&] { return monitor_said("RouDi runs"); })) << monitor.output();
  const auto first = roudis();
  ASSERT_EQ(first.size(), 1u);
  ::kill(static_cast<pid_t>(first.front()), SIGKILL);
  ASSERT_TRUE(eventually([&] { return monitor_said("started RouDi again"); })) << monitor.output();
  EXPECT_TRUE(monitor_said("killed by signal 9")) << monitor.output();
  EXPECT_TRUE(
      monitor_said("modules that joined the RouDi before end and their registry starts "
                   "them again"));
  ASSERT_TRUE(eventually([] { return zero_copy::roudi_running(); }));
  const auto second = roudis();
  ASSERT_EQ(second.size(), 1u);
  EXPECT_NE(second.front(), first.front());
  cues_flow("PlainBool", "5", "1", "0");  // the new one carries cues
}

// iceoryx 2.0's RouDi hangs for good when a process dies holding a lock of one of its publishers
// (a producer killed while it publishes). A stopped RouDi hangs the same way: its discovery
// thread stops running, and after 3 s the monitor kills it and starts another.
TEST_F(HostRoudi, AHungRouDiIsKilledAndStartedAgain) {
  auto& monitor = start_monitor();
  ASSERT_TRUE(eventually([&] { return monitor_said("RouDi runs"); })) << monitor.output();
  const auto first = roudis();
  ASSERT_EQ(first.size(), 1u);
  std::this_thread::sleep_for(4s);  // longer than the 3 s: an idle RouDi does not count as hung
  EXPECT_FALSE(monitor_said("hangs")) << monitor.output();
  ::kill(static_cast<pid_t>(first.front()), SIGSTOP);
  ASSERT_TRUE(eventually([&] { return test::stopped(first.front()); }));  // kill() returns first
  // A module started meanwhile waits for RouDi's answer to its registration.
  auto module = test::run_module(
      "plain_src", {"-k", "bench_source:src", "-p", "src.type=PlainBool", "-m", "continuous:20ms"});
  ASSERT_TRUE(eventually([&] { return monitor_said("started RouDi again"); })) << monitor.output();
  // It ends once that RouDi is gone, so that its registry starts it again on the new one (iceoryx
  // would try the dead connection for a minute, an error line per try).
  EXPECT_EQ(module->wait(10s), kKernelFailureExit) << module->output().substr(0, 4000);
  const auto said = module->output();
  EXPECT_THAT(said, HasSubstr("the RouDi this process was registering with went away before it "
                              "answered (/tmp/roudi "));
  EXPECT_LT(std::count(said.begin(), said.end(), '\n'), 100) << said.substr(0, 4000);
  EXPECT_TRUE(monitor_said(
      fmt::format("RouDi (pid {}) hangs: its discovery thread has not run for 3 s", first.front())))
      << monitor.output();
  EXPECT_TRUE(monitor_said("killed by signal 9")) << monitor.output();
  ASSERT_TRUE(eventually([] { return zero_copy::roudi_running(); }));
  const auto second = roudis();
  ASSERT_EQ(second.size(), 1u);
  EXPECT_NE(second.front(), first.front());
  cues_flow("PlainBool", "5", "1", "0");  // the new one carries cues
}

// A module that joined a RouDi which was killed and started again would publish where nobody
// started since looks: it ends with kKernelFailureExit, saying why, and the registry starts it
// again (on the new RouDi).
TEST_F(HostRoudi, AModuleWhoseRouDiWasReplacedEndsSoThatTheRegistryStartsItAgain) {
  // Chunks for the source's ring of 16 (the fixture's 8 would run out and iceoryx would log an
  // error per cue).
  std::ofstream(file_) << fmt::format(R"(system: zc
domain: {}
zero_copy: {{ chunks: 32 }}
modules: [ {{ name: src, kernels: [ {{ type: bench_source, name: src }} ] }} ]
)",
                                      test::test_domain());
  auto& monitor = start_monitor();
  ASSERT_TRUE(eventually([&] { return monitor_said("RouDi runs"); })) << monitor.output();
  auto module = test::run_module(
      "plain_src", {"-k", "bench_source:src", "-p", "src.type=PlainBool", "-m", "continuous:20ms"});
  const auto joined = [&] {
    return test::proc_file(module->pid(), "maps").find("/dev/shm/iceoryx_mgmt") !=
           std::string::npos;
  };
  ASSERT_TRUE(eventually(joined)) << module->output();
  // Its output is offered once a peer reads its cues; killed before, RouDi would leave the
  // module's port request unanswered (IceoryxErrors tests that end).
  auto reader =
      peer({"sub", "PlainBool", fmt::format("{}/oscar/cue/src/out", test::test_domain()), "0", "1"},
           "reader");
  ASSERT_TRUE(eventually([&] { return reader.output().find("received") != std::string::npos; }))
      << reader.output() << module->output();
  const auto first = roudis();
  ASSERT_EQ(first.size(), 1u);
  ::kill(static_cast<pid_t>(first.front()), SIGKILL);
  std::this_thread::sleep_for(100ms);
  EXPECT_FALSE(module->wait(0ms)) << "a killed RouDi not yet replaced ends nothing";
  ASSERT_TRUE(eventually([&] { return monitor_said("started RouDi again"); })) << monitor.output();
  EXPECT_EQ(module->wait(10s), kKernelFailureExit) << module->output();
  EXPECT_THAT(module->output(),
              HasSubstr("stopping the module: the RouDi it joined is gone and another runs "
                        "(/dev/shm/iceoryx_mgmt is a new segment)"));
  EXPECT_THAT(module->output(), HasSubstr("the registry starts it again on the host's RouDi"));
  // Started again, it joins the new RouDi and stays.
  module = test::run_module(
      "plain_src", {"-k", "bench_source:src", "-p", "src.type=PlainBool", "-m", "continuous:20ms"});
  ASSERT_TRUE(eventually(joined)) << module->output();
  EXPECT_FALSE(module->wait(1s)) << module->output();
}

TEST_F(HostRoudi, ARouDiAlreadyRunningIsUsedAndWhenItGoesTheMonitorStartsItsOwn) {
  std::ofstream("/tmp/other.toml") << zero_copy::roudi_config(zero_copy::plain_cue_mempools(4));
  test::Process other({"/usr/bin/iox-roudi", "-c", "/tmp/other.toml"}, "/tmp/other.log");
  ASSERT_TRUE(eventually([] { return zero_copy::roudi_running(); })) << other.output();
  auto& monitor = start_monitor();
  ASSERT_TRUE(eventually([&] { return monitor_said("a RouDi this monitor did not start"); }))
      << monitor.output();
  std::this_thread::sleep_for(500ms);  // five of the monitor's looks
  EXPECT_EQ(roudis().size(), 1u);
  EXPECT_FALSE(monitor_said("started RouDi")) << monitor.output();
  ::kill(other.pid(), SIGTERM);
  EXPECT_EQ(other.wait(10s), 0) << other.output();
  ASSERT_TRUE(eventually([&] { return monitor_said("RouDi runs"); })) << monitor.output();
  EXPECT_TRUE(monitor_said("the RouDi this host's processes used is gone"));
  EXPECT_TRUE(zero_copy::roudi_running());
}

// Without iox-roudi the host's cues go serialized: the monitor says so and goes on; boot and the
// ssh host check refuse such a system beforehand, naming the package.
TEST_F(HostRoudi, WithoutIoxRoudiMonitorBootAndTheHostCheckNameThePackage) {
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", "/nonexistent", 1);  // the children find no iox-roudi
  auto& monitor = start_monitor();
  test::Process boot({test::bin("oscar-boot"), file_, "--check"}, "/tmp/boot.log");
  test::Process check({test::bin("oscar-monitor"), "--system", file_, "--host", "localhost",
                       "--check", content_fingerprint(read(file_))},
                      "/tmp/check.log");
  ::setenv("PATH", path.c_str(), 1);
  ASSERT_TRUE(eventually([&] { return monitor_said("zero_copy:"); })) << monitor.output();
  EXPECT_TRUE(
      monitor_said("zero_copy: iox-roudi is not installed on this host (Debian package "
                   "iceoryx): its cues go serialized through DDS"))
      << monitor.output();
  EXPECT_FALSE(monitor.wait(300ms)) << "the monitor goes on: " << monitor.output();
  EXPECT_EQ(boot.wait(30s), 2) << boot.output();
  EXPECT_THAT(boot.output(), HasSubstr(file_ + ":3: zero_copy: iox-roudi is not installed on "
                                               "this host (Debian package iceoryx)"));
  EXPECT_EQ(check.wait(30s), 2) << check.output();
  EXPECT_THAT(check.output(),
              HasSubstr("\nzero_copy: iox-roudi is not installed on this host (Debian package "
                        "iceoryx)\n"));
}

// A booted system's plain images from a producer that is killed with -9 again and again, at
// whatever point of publishing: its registry starts it again, and its consumer in another module
// gets its images again, in shared memory. When a kill leaves RouDi hanging (iceoryx 2.0 waits
// for good on the lock of a producer that died holding it), the monitor starts another RouDi and
// the registry the modules that had joined the one before.
TEST(ZeroCopySystem, AProducerKilledOverAndOverIsStartedAgainAndItsConsumerGetsItsCuesAgain) {
  if (!test::kNoPrivateTmp.empty())
    GTEST_SKIP() << "needs a private mount namespace (root): " << test::kNoPrivateTmp;
  test::BootedSystem sys("zc_kill", R"(
system: zc_kill
zero_copy: { chunks: 64 }
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: PlainGvImage } } ]
    mode: { continuous: 10ms }
    restart: { policy: auto, max: 30, backoff: 50ms }
  - name: sink
    kernels:
      - { type: bench_sink, name: sink, params: { type: PlainGvImage }, inputs: { in: src/out } }
    mode: single_step
    restart: { policy: auto, max: 30, backoff: 50ms }
)");
  auto s = sys.running();
  // The sink's incarnation and the cues it has taken in it.
  const auto sink_taken = [](const SystemState& st) {
    const auto* m = test::entry(st, "sink");
    const auto* k = m ? test::kernel_state(*m, "sink") : nullptr;
    return std::pair(m ? m->incarnation() : 0u, k ? k->cycles() : 0u);
  };
  constexpr int kKills = 6;
  for (int kill = 0; kill <= kKills; ++kill) {
    const auto [incarnation, taken] = sink_taken(s);
    s = sys.wait_for(
        [&, incarnation = incarnation, taken = taken](const SystemState& st) {
          const auto [now_incarnation, now_taken] = sink_taken(st);
          return st.state() == "running" &&
                 now_taken >= (now_incarnation == incarnation ? taken : 0) + 10;
        },
        60s);
    ASSERT_EQ(s.state(), "running") << "kill " << kill;
    if (kill == kKills) break;
    const auto src_incarnation = test::entry(s, "src")->incarnation();
    ASSERT_EQ(::kill(static_cast<pid_t>(test::entry(s, "src")->pid()), SIGKILL), 0);
    s = sys.wait_for(
        [&](const SystemState& st) {
          return test::entry(st, "src")->incarnation() > src_incarnation && st.state() == "running";
        },
        60s);
  }
  const auto sink_log = read(sys.log_dir() + "/localhost/sink.log");
  // At its start if RouDi ran by then, else once the monitor's RouDi runs and src offers there.
  EXPECT_THAT(sink_log, ContainsRegex("input sink/in: (cues of )?src/out (is offered in shared "
                                      "memory on this host now: its cues )?come zero-copy"))
      << sink_log;
  const auto monitor_log = read(sys.log_dir() + "/monitor-localhost.log");
  const auto count = [&](const std::string& text) {
    std::size_t n = 0;
    for (auto at = monitor_log.find(text); at != std::string::npos;
         at = monitor_log.find(text, at + 1))
      ++n;
    return n;
  };
  std::cout << kKills << " kills of the producer: RouDi was replaced "
            << count("started RouDi again") << " times, after hanging " << count(" hangs: ")
            << " times\n";
}

// A RouDi slow to listen (here: 2 s, less than the monitor's patience) holds the monitor's first
// launches back, so that the booted modules begin in shared memory instead of moving there from
// DDS a moment later.
TEST(ZeroCopySystem, ModulesStartOnceTheHostsRouDiListens) {
  if (!test::kNoPrivateTmp.empty())
    GTEST_SKIP() << "needs a private mount namespace (root): " << test::kNoPrivateTmp;
  std::filesystem::create_directories("/tmp/slow");
  std::ofstream("/tmp/slow/iox-roudi") << "#!/bin/sh\nsleep 2\nexec /usr/bin/iox-roudi \"$@\"\n";
  std::filesystem::permissions("/tmp/slow/iox-roudi", std::filesystem::perms::owner_all);
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", ("/tmp/slow:" + path).c_str(), 1);  // boot's monitor finds the slow one
  test::BootedSystem sys("zc_slow", R"(
system: zc_slow
zero_copy: { chunks: 16 }
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: PlainBool } } ]
    mode: { continuous: 20ms }
  - name: sink
    kernels:
      - { type: bench_sink, name: sink, params: { type: PlainBool }, inputs: { in: src/out } }
    mode: single_step
)");
  ::setenv("PATH", path.c_str(), 1);
  sys.wait_for([](const SystemState& st) {
    const auto* m = test::entry(st, "sink");
    const auto* k = m ? test::kernel_state(*m, "sink") : nullptr;
    return st.state() == "running" && k && k->cycles() >= 5;
  });
  const auto monitor_log = read(sys.log_dir() + "/monitor-localhost.log");
  const auto roudi_runs = monitor_log.find("RouDi runs");
  ASSERT_NE(roudi_runs, std::string::npos) << monitor_log;
  EXPECT_LT(roudi_runs, monitor_log.find("started src (")) << monitor_log;
  EXPECT_LT(roudi_runs, monitor_log.find("started sink (")) << monitor_log;
  const auto sink_log = read(sys.log_dir() + "/localhost/sink.log");
  EXPECT_THAT(sink_log, HasSubstr("input sink/in: cues of src/out come zero-copy")) << sink_log;
  EXPECT_THAT(sink_log, Not(HasSubstr("go through DDS only"))) << sink_log;
}

}  // namespace
}  // namespace oscar
