// A hostile participant against a module process (docs/architecture.md, "Configuration"): it
// floods the module's configuration topic, or sends commands with huge senders and arguments.
// The module keeps answering another writer's commands, its memory stays flat, and its log
// quotes excerpts only.
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/config_client.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "process.hpp"  // tests/common

namespace oscar {
namespace {
using namespace std::chrono_literals;
using testing::HasSubstr;

// The resident set of process `pid` in KiB (VmRSS in /proc/PID/status), or -1.
long vm_rss_kib(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);) {
    if (line.starts_with("VmRSS:")) return std::stol(line.substr(6));
  }
  return -1;
}

// Under AddressSanitizer freed memory stays in its quarantine (256 MB by default), so the
// module's resident set grows with any churn; a small quarantine leaves what is really kept.
// Measured under ASan with the bounds in place: +121908 KiB with the default, +4872 KiB with 4 MB.
std::string with_small_asan_quarantine(const std::string& module) {
#if defined(__SANITIZE_ADDRESS__)
  const char* options = std::getenv("ASAN_OPTIONS");
  const std::string merged =
      std::string(options ? options : "") + (options ? ":" : "") + "quarantine_size_mb=4";
  setenv("ASAN_OPTIONS", merged.c_str(), 1);  // inherited by the module process
#endif
  return module;
}

// A module process with one kernel, up and answering `boot` commands.
struct FloodedModule {
  explicit FloodedModule(const std::string& module)
      : name(module),
        process(test::run_module(with_small_asan_quarantine(module),
                                 {"-k", "bench_source:src", "-m", "continuous:100ms"})),
        participant(test::test_domain(), "test:operator"),
        boot(participant, "boot") {}
  // Waits until the module answers, then lets it settle: the resident set grows while Fast DDS
  // discovers and allocates its first buffers.
  bool ready() {
    const bool up = eventually(
        [&] {
          try {
            return boot.send(name, CMD_RESUME, {}, 5s).ok();
          } catch (const std::runtime_error&) {
            return false;  // not discovered yet
          }
        },
        30s);
    std::this_thread::sleep_for(2s);
    return up;
  }
  long rss_kib() const { return vm_rss_kib(process->pid()); }

  std::string name;
  std::unique_ptr<test::Process> process;
  DdsParticipant participant;
  ConfigClient boot;
};

// The hostile participant: a writer of its own on the module's configuration topic.
struct Flooder {
  explicit Flooder(const std::string& module)
      : participant(test::test_domain(), "test:flooder"),
        writer(participant, topics::config(module)) {}
  bool matched() {
    return eventually([&] { return writer.matched() > 0; }, 10s);
  }
  DdsParticipant participant;
  TopicWriter<ConfigCommand, ConfigCommandPubSubType> writer;
};

ConfigCommand trigger(std::uint64_t id, std::string sender) {
  ConfigCommand c;
  c.id(id);
  c.sender(std::move(sender));
  c.target("flooded");
  c.kind(CMD_TRIGGER);
  c.args({"src"});
  return c;
}

// 30 such commands added ~29 MB to a module before it bounded what it remembers per sender.
TEST(HostileWriter, HugeDistinctSendersLeaveTheModulesMemoryAndLogFlat) {
  FloodedModule module("flooded");
  ASSERT_TRUE(module.ready()) << module.process->output();
  Flooder flooder("flooded");
  ASSERT_TRUE(flooder.matched());
  const long before_kib = module.rss_kib();
  constexpr int kCommands = 200;
  for (int i = 0; i < kCommands; ++i) {
    // Distinct senders: one memory entry each, unless the module bounds them.
    auto sender = std::string(256 * 1024, 'a' + i % 26);
    sender.replace(0, 8, fmt::format("{:08}", i));
    flooder.writer.write(trigger(1, std::move(sender)));
    // Slow enough for the rate limit (100/s): every one of them is applied and answered.
    std::this_thread::sleep_for(20ms);
  }
  // Answered after all of them: the module has taken every one.
  const auto reply = module.boot.send("flooded", CMD_STUB, {"src", "on"}, 30s);
  ASSERT_TRUE(reply.ok()) << reply.error();
  std::this_thread::sleep_for(2s);
  const long after_kib = module.rss_kib();
  std::printf(
      "VmRSS of the module: %ld KiB before %d commands with 256 KiB senders, %ld KiB "
      "after (+%ld KiB)\n",
      before_kib, kCommands, after_kib, after_kib - before_kib);
  // Without the bound the module remembered each refusal with its sender: +199384 KiB here.
  EXPECT_LT(after_kib - before_kib, 40 * 1024);
  // Not printed on failure: without bounds the log holds every sender whole (52 MB).
  const auto log = module.process->output();
  EXPECT_NE(log.find("refused: sender is 262144 bytes long ('00000000aaaa"), std::string::npos)
      << "the refusal does not name the field and the limit";
  EXPECT_LT(log.size(), 1024u * 1024u) << "the log quotes excerpts only";
}

TEST(HostileWriter, AFloodingWriterIsRateLimitedAndAnotherWritersCommandsAreAnswered) {
  FloodedModule module("flooded");
  ASSERT_TRUE(module.ready()) << module.process->output();
  Flooder flooder("flooded");
  ASSERT_TRUE(flooder.matched());
  const long before_kib = module.rss_kib();
  std::atomic<bool> flooding{true};
  std::atomic<std::uint64_t> written{0};
  std::thread flood([&] {
    // As fast as the writer goes, for 8 s; distinct ids, so nothing is a repeat.
    const auto until = std::chrono::steady_clock::now() + 8s;
    while (std::chrono::steady_clock::now() < until) {
      if (flooder.writer.write(trigger(written + 1, "flood"))) ++written;
    }
    flooding = false;
  });
  std::this_thread::sleep_for(2s);  // the flood is under way
  std::vector<double> answered_s;
  for (int i = 0; i < 4 && flooding; ++i) {
    const auto sent = std::chrono::steady_clock::now();
    try {
      // The bound is generous: the machine is loaded, and speed is not what is tested.
      const auto reply = module.boot.send("flooded", CMD_STUB, {"src", i % 2 ? "off" : "on"}, 20s);
      EXPECT_TRUE(reply.ok()) << reply.error();
    } catch (const std::runtime_error& e) {
      ADD_FAILURE() << "not answered during the flood: " << e.what();
      break;
    }
    answered_s.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count());
  }
  flood.join();
  const auto reply = module.boot.send("flooded", CMD_STUB, {"src", "off"}, 20s);
  EXPECT_TRUE(reply.ok()) << reply.error();
  std::this_thread::sleep_for(2s);
  const long after_kib = module.rss_kib();
  std::printf("%llu commands flooded in 8 s; another writer's commands answered in",
              static_cast<unsigned long long>(written.load()));
  for (const auto s : answered_s) std::printf(" %.3f s", s);
  std::printf("; VmRSS %ld KiB before, %ld KiB after (+%ld KiB)\n", before_kib, after_kib,
              after_kib - before_kib);
  EXPECT_EQ(answered_s.size(), 4u) << "the flood ended before the module answered 4 commands";
  EXPECT_LT(after_kib - before_kib, 40 * 1024);
  EXPECT_TRUE(eventually(
      [&] {
        return module.process->output().find("over the rate limit of 100/s") != std::string::npos;
      },
      5s))
      << "the drops are not logged";
}

}  // namespace
}  // namespace oscar
