#include "oscar/shared_memory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "oscar/dds_participant.hpp"
#include "participant_identity.hpp"  // framework/src

namespace oscar {
namespace {
namespace fs = std::filesystem;

// A directory laid out like /dev/shm after Fast DDS processes came and went.
class SharedMemoryDir : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("oscar_shm_test_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    for (const int fd : held_) close(fd);
    fs::remove_all(dir_);
  }
  void touch(const std::string& name) { std::ofstream(dir_ / name) << "x"; }
  // Holds the lock of `name` as a living owner does.
  void hold(const std::string& name) {
    const int fd = open((dir_ / name).c_str(), O_RDONLY);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
    held_.push_back(fd);
  }
  fs::path dir_;
  std::vector<int> held_;
};

TEST_F(SharedMemoryDir, RemovesOnlyWhatDeadProcessesLeft) {
  for (const auto* name : {"fastrtps_0123456789abcdef", "fastrtps_port7411", "fastrtps_live",
                           "fastrtps_port7413", "other"}) {
    touch(name);
    touch(std::string(name) + "_el");
  }
  hold("fastrtps_live_el");
  hold("fastrtps_port7413_el");
  using namespace std::chrono_literals;
  DeadSharedMemorySweeper sweeper(5s, dir_);
  const auto t0 = DeadSharedMemorySweeper::Clock::now();
  EXPECT_EQ(sweeper.sweep(t0), 0u) << "first seen dead now";
  EXPECT_EQ(sweeper.sweep(t0 + 4s), 0u) << "dead for less than the grace";
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_port7411"));
  EXPECT_EQ(sweeper.sweep(t0 + 5s), 2u);
  EXPECT_FALSE(fs::exists(dir_ / "fastrtps_0123456789abcdef"));
  EXPECT_FALSE(fs::exists(dir_ / "fastrtps_0123456789abcdef_el"));
  EXPECT_FALSE(fs::exists(dir_ / "fastrtps_port7411"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_live"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_port7413_el"));
  EXPECT_TRUE(fs::exists(dir_ / "other")) << "not Fast DDS's";
}

TEST_F(SharedMemoryDir, TheGraceStartsWhenTheOwnerIsSeenGone) {
  using namespace std::chrono_literals;
  touch("fastrtps_port7411");
  touch("fastrtps_port7411_el");
  const int owner = open((dir_ / "fastrtps_port7411_el").c_str(), O_RDONLY);
  ASSERT_EQ(flock(owner, LOCK_EX | LOCK_NB), 0);
  DeadSharedMemorySweeper sweeper(5s, dir_);
  const auto t0 = DeadSharedMemorySweeper::Clock::now();
  EXPECT_EQ(sweeper.sweep(t0), 0u);
  close(owner);  // the owner dies at t0 + 10 s
  EXPECT_EQ(sweeper.sweep(t0 + 10s), 0u) << "its files live on for the grace";
  EXPECT_EQ(sweeper.sweep(t0 + 15s), 1u);
  EXPECT_FALSE(fs::exists(dir_ / "fastrtps_port7411_el"));
}

TEST(ParticipantIdentity, AnIdIsClaimedOnceUntilReleased) {
  const int domain = 150 + getpid() % 50;
  const auto file = fs::path("/dev/shm") / fmt::format("oscar_participant_d{}_127.0.0.1_3", domain);
  {
    internal::ParticipantIdClaim first(domain, "127.0.0.1", 3);
    ASSERT_TRUE(first);
    EXPECT_TRUE(fs::exists(file));
    EXPECT_FALSE(internal::ParticipantIdClaim(domain, "127.0.0.1", 3)) << "held";
    EXPECT_TRUE(internal::ParticipantIdClaim(domain, "10.77.1.2", 3))
        << "ids are per address (test hosts have their own ports)";
  }
  EXPECT_FALSE(fs::exists(file)) << "an orderly release leaves no file behind";
  EXPECT_TRUE(internal::ParticipantIdClaim(domain, "127.0.0.1", 3)) << "released";
}

// What a killed holder leaves: a lock file nobody holds. The next claim takes it over.
TEST(ParticipantIdentity, TheIdOfAKilledProcessIsFreeAgain) {
  const int domain = 150 + getpid() % 50;
  const auto file = fs::path("/dev/shm") / fmt::format("oscar_participant_d{}_127.0.0.1_4", domain);
  std::ofstream(file) << "";
  {
    internal::ParticipantIdClaim claim(domain, "127.0.0.1", 4);
    EXPECT_TRUE(claim);
  }
  EXPECT_FALSE(fs::exists(file));
}

TEST(ParticipantIdentity, SharedMemoryPortsAreNeverReused) {
  const auto a = internal::unique_shared_memory_locator();
  const auto b = internal::unique_shared_memory_locator();
  EXPECT_EQ(a.kind, LOCATOR_KIND_SHM);
  EXPECT_EQ(a.address[0], 'U');
  EXPECT_NE(a.port, b.port);
  EXPECT_GE(a.port, 1u << 24) << "clear of the RTPS well-known ports";
  EXPECT_EQ((a.port - (1u << 24)) >> 4, static_cast<std::uint32_t>(getpid()));
}

// Fast DDS takes the locator: the participant listens on its own port, named after this process.
TEST(ParticipantIdentity, AParticipantListensOnItsOwnSharedMemoryPort) {
  const auto ours = [] {
    int n = 0;
    for (const auto& e : fs::directory_iterator("/dev/shm")) {
      const auto name = e.path().filename().string();
      if (!name.starts_with("fastrtps_port") || name.ends_with("_el")) continue;
      const auto port = std::stoull(name.substr(13));
      if (port >= (1u << 24) && ((port - (1u << 24)) >> 4) == static_cast<unsigned>(getpid())) ++n;
    }
    return n;
  };
  const int before = ours();
  DdsParticipant p(150 + getpid() % 50, "own-port");
  EXPECT_EQ(ours(), before + 1);
}

}  // namespace
}  // namespace oscar
