#include "oscar/shared_memory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fstream>

#include <gtest/gtest.h>

#include "oscar/dds_participant.hpp"

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

TEST_F(SharedMemoryDir, APortIsAZombieWhenNobodyHoldsItsLock) {
  touch("fastrtps_port7411");
  touch("fastrtps_port7411_el");
  touch("fastrtps_port7413");
  touch("fastrtps_port7413_el");
  hold("fastrtps_port7413_el");
  EXPECT_TRUE(shared_memory_port_is_zombie(7411, dir_));
  EXPECT_FALSE(shared_memory_port_is_zombie(7413, dir_)) << "its owner holds the lock";
  EXPECT_FALSE(shared_memory_port_is_zombie(7415, dir_)) << "no such port";
}

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

// A participant does not take over the participant id whose shared-memory port a killed process
// left behind: the others would send into the dead port (the restart benchmark lost 1-2 s).
TEST(DdsParticipantId, SkipsAnIdWhoseSharedMemoryPortIsAZombie) {
  const int domain = 150 + getpid() % 50;
  const auto user_port = [&](int id) { return 7400 + 250 * domain + 11 + 2 * id; };
  const fs::path lock = "/dev/shm/fastrtps_port" + std::to_string(user_port(0)) + "_el";
  if (!fs::is_directory("/dev/shm") || fs::exists(lock)) GTEST_SKIP() << "/dev/shm not usable";
  std::ofstream(lock) << "";
  {
    DdsParticipant p(domain, "zombie-neighbour");
    EXPECT_EQ(p.get().get_qos().wire_protocol().participant_id, 1);
  }
  fs::remove(lock);
  DdsParticipant p(domain, "clean");
  EXPECT_EQ(p.get().get_qos().wire_protocol().participant_id, 0);
}

}  // namespace
}  // namespace oscar
