// The system-test fixture (docs/testing.md) on the demo system shipped in config/.
#include "oscar/testing/booted_system.hpp"

#include <signal.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/cue_types.hpp"
#include "oscar/registry/running_systems.hpp"

namespace oscar::testing {
namespace {
using namespace std::chrono_literals;
using ::testing::IsEmpty;
using ::testing::Not;

const KernelState* kernel(const SystemState& s, const std::string& name) {
  for (const auto& m : s.modules()) {
    for (const auto& k : m.state().kernels()) {
      if (k.name() == name) return &k;
    }
  }
  return nullptr;
}

bool kernel_mode_is(const SystemState& s, const std::string& name, const std::string& mode) {
  const auto* k = kernel(s, name);
  return k && k->mode() == mode;
}

// The fixture as users write it: boot() boots the SYSTEM of oscar_add_system_test, here
// config/demo-local.yaml (on a free domain, not the file's 42).
using DemoSystem = BootedSystem;

TEST_F(DemoSystem, RunsReadsCuesObeysConfigurationAndLeavesNothingBehind) {
  auto& sys = boot();
  EXPECT_NE(sys.domain(), 42) << "the file's domain is replaced by a free one";
  ASSERT_TRUE(wait_until_running({"lines", "camera", "fusion"}));
  ASSERT_TRUE(wait_for_cues({"lines/out", "camera/out"}, 2));

  // Typed cues, as the producer wrote them.
  const auto lines = read_cues<LineSeg3DSeq>("lines/out", 3);
  ASSERT_EQ(lines.size(), 3u);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(lines[i].lines().size(), 100u);
    EXPECT_EQ(lines[i].header().source(), "lines/out");
    if (i > 0) {
      EXPECT_GT(lines[i].header().seq(), lines[i - 1].header().seq());
    }
  }

  // Configuration with boot's authority: a new cycle, then the camera off and on again.
  const auto cycle = configure("lines", CMD_SET_CYCLE, {"lines", "50ms"});
  ASSERT_TRUE(cycle.ok()) << cycle.error();
  EXPECT_TRUE(sys.wait_for(
      [](const SystemState& s) {
        const auto* k = kernel(s, "lines");
        return k && k->cycle_ns() == 50'000'000;
      },
      10s));

  const auto off = configure("camera", CMD_DEACTIVATE, {"camera"});
  ASSERT_TRUE(off.ok()) << off.error();
  EXPECT_TRUE(sys.wait_for(
      [](const SystemState& s) { return kernel_mode_is(s, "camera", "deactivated"); }, 10s));
  auto camera = watch<GvImage>("camera/out");
  std::this_thread::sleep_for(500ms);  // what was on its way when the camera stopped
  camera->take();
  std::this_thread::sleep_for(1s);  // the camera's cycle is 200 ms: five cues if it still ran
  EXPECT_THAT(camera->take(), IsEmpty()) << "a deactivated kernel publishes nothing";
  const auto on = configure("camera", CMD_ACTIVATE, {"camera"});
  ASSERT_TRUE(on.ok()) << on.error();
  EXPECT_TRUE(camera->wait_for(2, 30s)) << "cues again once the camera is activated";

  // The shutdown (TearDown() does it too, and fails the test for anything left behind).
  EXPECT_THAT(sys.shared_memory_files(), Not(IsEmpty()));
  EXPECT_EQ(shut_down(), 0) << sys.boot_output();
  EXPECT_THAT(sys.leftover_processes(), IsEmpty());
  EXPECT_THAT(sys.leftover_shared_memory(), IsEmpty());
}

// A test that dies without an orderly shutdown: boot is killed with SIGKILL (as a crashing test
// would leave it), and the fixture still leaves no process and no shared-memory file behind.
TEST(SystemUnderTest, LeavesNothingBehindWhenBootIsKilled) {
  const char* file = std::getenv("OSCAR_TEST_SYSTEM");
  ASSERT_NE(file, nullptr);
  SystemUnderTest sys(file);
  ASSERT_TRUE(sys.wait_until_running());
  const auto before = sys.shared_memory_files();
  EXPECT_THAT(before, Not(IsEmpty()));
  kill(sys.boot_pid(), SIGKILL);
  EXPECT_EQ(sys.shut_down(), std::nullopt) << "boot did not exit by itself";
  EXPECT_THAT(sys.leftover_processes(), IsEmpty());
  EXPECT_THAT(sys.leftover_shared_memory(), IsEmpty());
}

// A killed earlier run in the same domain left a port (with its lock file and semaphore): the
// system's processes would open it and take it for theirs. The fixture removes dead ports of its
// domain before it boots, and leaves other domains' files alone.
TEST(SystemUnderTest, RemovesDeadPortsOfItsDomainBeforeItBoots) {
  const char* file = std::getenv("OSCAR_TEST_SYSTEM");
  ASSERT_NE(file, nullptr);
  FreeDomain domain;
  const int mine = 7400 + 250 * domain.domain() + 17;
  const int other = 7400 + 250 * (domain.domain() + 1) + 17;  // the next domain's
  const std::filesystem::path shm = "/dev/shm";
  std::vector<std::string> stale, kept;
  for (const auto* pattern :
       {"fastrtps_port{}", "fastrtps_port{}_el", "sem.fastrtps_port{}_mutex"}) {
    stale.push_back(fmt::format(fmt::runtime(pattern), mine));
    kept.push_back(fmt::format(fmt::runtime(pattern), other));
  }
  for (const auto& name : stale) std::ofstream(shm / name) << "left by a killed process";
  for (const auto& name : kept) std::ofstream(shm / name) << "another domain's";
  {
    BootOptions options;
    options.domain = domain.domain();
    SystemUnderTest sys(file, options);
    for (const auto& name : stale) EXPECT_FALSE(std::filesystem::exists(shm / name)) << name;
    for (const auto& name : kept) EXPECT_TRUE(std::filesystem::exists(shm / name)) << name;
  }
  for (const auto& name : kept) std::filesystem::remove(shm / name);
}

TEST(SystemUnderTest, AFileThatDoesNotExistIsRefusedByName) {
  try {
    SystemUnderTest sys("no/such/system.yaml");
    FAIL() << "booted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "oscar::testing: the system file 'no/such/system.yaml' does not exist");
  }
}

TEST(SystemUnderTest, ABootThatFailsIsReportedWithBootsOutput) {
  const auto file = std::filesystem::temp_directory_path() /
                    ("oscar_bad_system_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(file)
      << "system: bad\nmodules:\n  - name: m\n    kernels: [ { type: no_such_kernel, "
         "name: k } ]\n";
  SystemUnderTest sys(file.string());
  const auto result = sys.wait_until_running({}, 30s);
  std::filesystem::remove(file);
  EXPECT_FALSE(result);
  EXPECT_THAT(result.message(), ::testing::HasSubstr("oscar boot exited with code 2"));
  EXPECT_THAT(result.message(), ::testing::HasSubstr("no_such_kernel"));
}

// Parallel tests and systems booted on this machine never get the same domain.
TEST(FreeDomain, SkipsDomainsThatAreHeldOrBooted) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("oscar_free_domain_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::create_directories(dir / "locks");
  setenv("OSCAR_SYSTEMS_DIR", dir.c_str(), 1);
  setenv("OSCAR_TEST_DOMAINS_DIR", (dir / "locks").c_str(), 1);
  {
    FreeDomain held;
    // Every other domain but one has a running system.
    const int left = held.domain() == 232 ? 1 : held.domain() + 1;
    std::vector<std::unique_ptr<RunningSystemRecord>> records;
    for (int d = 1; d <= 232; ++d) {
      if (d == held.domain() || d == left) continue;
      records.push_back(
          std::make_unique<RunningSystemRecord>(RunningSystem{.domain = d,
                                                              .system = "s",
                                                              .file = "s.yaml",
                                                              .log_dir = "logs",
                                                              .boot_pid = getpid(),
                                                              .started = 0,
                                                              .boot_started_ticks = -1}));
    }
    FreeDomain next;
    EXPECT_EQ(next.domain(), left);
    try {
      FreeDomain none;
      ADD_FAILURE() << "got domain " << none.domain();
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr("every DDS domain from 1 to 232 is taken"));
    }
  }
  unsetenv("OSCAR_SYSTEMS_DIR");
  unsetenv("OSCAR_TEST_DOMAINS_DIR");
  std::filesystem::remove_all(dir);
}

// A test that starts from a point of its own takes the first free domain from there down, and
// wraps to 232 below 1.
TEST(FreeDomain, StartsWhereItIsToldAndWraps) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("oscar_free_from_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir / "locks");
  setenv("OSCAR_SYSTEMS_DIR", dir.c_str(), 1);
  setenv("OSCAR_TEST_DOMAINS_DIR", (dir / "locks").c_str(), 1);
  {
    FreeDomain a(100), b(100), c(1), d(1);
    EXPECT_EQ(a.domain(), 100);
    EXPECT_EQ(b.domain(), 99);
    EXPECT_EQ(c.domain(), 1);
    EXPECT_EQ(d.domain(), 232);
    EXPECT_THROW(FreeDomain(0), std::invalid_argument);
    EXPECT_THROW(FreeDomain(233), std::invalid_argument);
  }
  unsetenv("OSCAR_SYSTEMS_DIR");
  unsetenv("OSCAR_TEST_DOMAINS_DIR");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace oscar::testing
