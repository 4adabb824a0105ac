#include "oscar/shared_memory.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <semaphore.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <ctime>

#include <fstream>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "dds/participant_identity.hpp"  // framework/src
#include "oscar/dds_participant.hpp"
#include "oscar/process_util.hpp"
#include "process.hpp"  // tests/common

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
  // Maps 4 KB of a new file `dir_/name` as a participant maps its port; unmapped at the end.
  void* map_new_file(const std::string& name) {
    std::ofstream(dir_ / name) << std::string(4096, 'x');
    const int fd = open((dir_ / name).c_str(), O_RDWR);
    EXPECT_GE(fd, 0);
    void* mapped = mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    close(fd);
    EXPECT_NE(mapped, MAP_FAILED);
    return mapped;
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
  touch("sem.fastrtps_port7411_mutex");  // the lock Fast DDS opens a port under
  touch("sem.fastrtps_port7413_mutex");
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
  EXPECT_FALSE(fs::exists(dir_ / "sem.fastrtps_port7411_mutex"));
  EXPECT_TRUE(fs::exists(dir_ / "sem.fastrtps_port7413_mutex"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_live"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_port7413_el"));
  EXPECT_TRUE(fs::exists(dir_ / "other")) << "not Fast DDS's";
}

// What the last process of a system removes as it exits: everything of the dead at once, and the
// participant id claims of its own domain that killed processes left (a living one's stays).
TEST_F(SharedMemoryDir, AtExitEverythingOfTheDeadAndTheDomainsAbandonedClaimsGo) {
  for (const auto* name : {"fastrtps_0123456789abcdef", "fastrtps_port7411", "fastrtps_live"}) {
    touch(name);
    touch(std::string(name) + "_el");
  }
  touch("sem.fastrtps_port7411_mutex");
  hold("fastrtps_live_el");
  const auto claims = internal::claim_prefix(7);
  touch(claims + "127.0.0.1_0");  // left by a killed process
  touch(claims + "127.0.0.1_1");
  hold(claims + "127.0.0.1_1");                      // its process lives
  touch(internal::claim_prefix(8) + "127.0.0.1_0");  // another system's
  EXPECT_EQ(remove_files_of_dead_processes(7, dir_), 3u);
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_)) left.insert(e.path().filename().string());
  EXPECT_EQ(left,
            (std::set<std::string>{"fastrtps_live", "fastrtps_live_el", claims + "127.0.0.1_1",
                                   internal::claim_prefix(8) + "127.0.0.1_0"}));
}

// Fast DDS leaves a port's semaphore behind when the port goes, and a sender that opens the port
// of a dead participant creates the port anew, with no owner: both would pile up for good.
TEST_F(SharedMemoryDir, RemovesPortsNobodyOwnsAndLocksOfPortsThatAreGone) {
  touch("fastrtps_port9001");  // created by a sender: no "_el" beside it
  touch("sem.fastrtps_port9001_mutex");
  touch("sem.fastrtps_port9002_mutex");  // its port is gone
  touch("fastrtps_port9003");            // a living port ...
  touch("fastrtps_port9003_el");
  hold("fastrtps_port9003_el");
  touch("sem.fastrtps_port9003_mutex");  // ... keeps its lock
  touch("fastrtps_port7400");            // a shared (multicast) port of plain Fast DDS programs
  touch("fastrtps_port7400_sl");
  using namespace std::chrono_literals;
  DeadSharedMemorySweeper sweeper(5s, dir_);
  const auto t0 = DeadSharedMemorySweeper::Clock::now();
  EXPECT_EQ(sweeper.sweep(t0), 0u) << "a port being created has no lock file for a moment";
  EXPECT_EQ(sweeper.sweep(t0 + 5s), 2u);
  EXPECT_FALSE(fs::exists(dir_ / "fastrtps_port9001"));
  EXPECT_FALSE(fs::exists(dir_ / "sem.fastrtps_port9001_mutex"));
  EXPECT_FALSE(fs::exists(dir_ / "sem.fastrtps_port9002_mutex"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_port9003"));
  EXPECT_TRUE(fs::exists(dir_ / "sem.fastrtps_port9003_mutex"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_port7400"));
}

// OSCAR's participants listen on ports that carry their pid. A living listener's port stays, also
// in a sweep at once (as a system's last process exits) and in the moments it has no lock: its
// semaphore taken before the port is created, the port created before its lock file, the lock
// let go while the port is opened anew. A dead listener's port goes, also while it is a zombie.
TEST_F(SharedMemoryDir, APortStaysWhileItsListenerLivesEvenWithoutItsLock) {
  const auto port_of = [](pid_t pid, unsigned participant) {
    return fmt::format("fastrtps_port{}",
                       (1u << 24) + (static_cast<unsigned>(pid) << 4) + participant);
  };
  const pid_t living = fork();
  if (living == 0) {
    pause();
    _exit(0);
  }
  ASSERT_GT(living, 0);
  const pid_t zombie = fork();
  if (zombie == 0) _exit(0);
  ASSERT_GT(zombie, 0);
  const auto opening = port_of(living, 0), created = port_of(living, 1),
             reopened = port_of(living, 2), dead = port_of(zombie, 0);
  touch("sem." + opening + "_mutex");
  touch(created);
  touch("sem." + created + "_mutex");
  touch(reopened);
  touch(reopened + "_el");
  touch(dead);
  touch(dead + "_el");
  touch("sem." + dead + "_mutex");
  while (process_lives(zombie)) usleep(1000);  // exited, not reaped yet
  EXPECT_EQ(remove_files_of_dead_processes(7, dir_), 1u);
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_)) left.insert(e.path().filename().string());
  EXPECT_EQ(left, (std::set<std::string>{"sem." + opening + "_mutex", created,
                                         "sem." + created + "_mutex", reopened, reopened + "_el"}));
  kill(living, SIGKILL);
  waitpid(living, nullptr, 0);
  waitpid(zombie, nullptr, 0);
  EXPECT_EQ(remove_files_of_dead_processes(7, dir_), 3u) << "its listener is gone now";
  EXPECT_TRUE(fs::is_empty(dir_));
}

// A process listens where new senders look while the port file of its name is the one it maps.
TEST_F(SharedMemoryDir, APortFileIsCurrentWhileItIsTheFileThisProcessMaps) {
  EXPECT_TRUE(maps_current_port_file(4711, dir_)) << "maps no such file: nothing to judge";
  const auto path = dir_ / "fastrtps_port4711";
  void* mapped = map_new_file(path.filename());
  EXPECT_TRUE(maps_current_port_file(4711, dir_));
  EXPECT_TRUE(maps_current_port_file(4712, dir_)) << "another port";
  fs::remove(path);
  EXPECT_FALSE(maps_current_port_file(4711, dir_)) << "removed";
  std::ofstream(path) << "y";
  EXPECT_FALSE(maps_current_port_file(4711, dir_)) << "another file of that name";
  munmap(mapped, 4096);
  EXPECT_TRUE(maps_current_port_file(4711, dir_));
}

// The watch of a process's own port file says it is lost only after 3 looks in a row (Fast DDS
// moves its listener off a port it replaced itself within a second), and names the file.
TEST_F(SharedMemoryDir, APortFileWatchSaysLostAfterThreeLooksInARow) {
  const auto path = dir_ / "fastrtps_port4711";
  void* mapped = map_new_file(path.filename());
  PortFileWatch watch(4711, dir_);
  EXPECT_FALSE(watch.lost());
  EXPECT_FALSE(watch.lost()) << "the file found mapped at the last look";
  fs::create_hard_link(path, dir_ / "kept");
  fs::remove(path);
  EXPECT_FALSE(watch.lost()) << "1 look";
  EXPECT_FALSE(watch.lost()) << "2 looks";
  fs::rename(dir_ / "kept", path);  // the same file back: the count starts again
  EXPECT_FALSE(watch.lost());
  fs::remove(path);
  EXPECT_FALSE(watch.lost()) << "1 look";
  EXPECT_FALSE(watch.lost()) << "2 looks";
  std::ofstream(path) << "y";  // another file of that name: still lost
  EXPECT_EQ(watch.lost(), path.string()) << "3 looks";
  munmap(mapped, 4096);
  EXPECT_FALSE(watch.lost()) << "maps no file of that name any more: nothing to judge";
  EXPECT_FALSE(PortFileWatch(std::nullopt, dir_).lost()) << "no shared-memory transport";
}

// A test that shut its own system down sweeps that system's files only, at once: another
// system's dead files still have their grace (senders may still write to them).
TEST_F(SharedMemoryDir, WithAFilterOnlyTheNamedFilesAreLookedAt) {
  for (const auto* name : {"fastrtps_mine", "fastrtps_theirs"}) {
    touch(name);
    touch(std::string(name) + "_el");
  }
  touch("sem.fastrtps_port9004_mutex");  // a port of mine that is gone
  touch("sem.fastrtps_port9005_mutex");  // one of theirs
  const std::set<std::string> mine{"fastrtps_mine_el", "sem.fastrtps_port9004_mutex"};
  DeadSharedMemorySweeper sweeper(std::chrono::seconds(0), dir_,
                                  [&](const std::string& name) { return mine.count(name) > 0; });
  EXPECT_EQ(sweeper.sweep(), 2u);
  EXPECT_FALSE(fs::exists(dir_ / "fastrtps_mine"));
  EXPECT_FALSE(fs::exists(dir_ / "fastrtps_mine_el"));
  EXPECT_FALSE(fs::exists(dir_ / "sem.fastrtps_port9004_mutex"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_theirs"));
  EXPECT_TRUE(fs::exists(dir_ / "fastrtps_theirs_el"));
  EXPECT_TRUE(fs::exists(dir_ / "sem.fastrtps_port9005_mutex"));
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

// A lock shaped like Fast DDS's port locks (a named POSIX semaphore), under a name of this test.
class PortLock : public testing::Test {
 protected:
  void SetUp() override {
    prefix_ = fmt::format("oscar_test{}_", getpid());
    name_ = prefix_ + "port7411_mutex";
    sem_unlink(("/" + name_).c_str());
    sem_ = sem_open(("/" + name_).c_str(), O_CREAT | O_EXCL, 0600, 1);
    ASSERT_NE(sem_, SEM_FAILED);
  }
  void TearDown() override {
    for (const pid_t child : children_) kill(child, SIGKILL), waitpid(child, nullptr, 0);
    if (sem_ != SEM_FAILED) sem_close(sem_);
    sem_unlink(("/" + name_).c_str());
  }
  // A child that takes the lock and then dies (`die`) or keeps it.
  pid_t holder(bool die) {
    const pid_t child = fork();
    if (child == 0) {
      sem_wait(sem_);
      if (die) _exit(0);
      pause();
      _exit(0);
    }
    if (!die) children_.push_back(child);
    return child;
  }
  // A child that waits up to 10 s for the lock; exits 0 if it got it.
  pid_t waiter() {
    const pid_t child = fork();
    if (child == 0) {
      timespec deadline{};
      clock_gettime(CLOCK_REALTIME, &deadline);
      deadline.tv_sec += 10;
      _exit(sem_timedwait(sem_, &deadline) == 0 ? 0 : 1);
    }
    return child;
  }
  // This process lets go of its own mapping: only the children's count.
  void let_go() {
    sem_close(sem_);
    sem_ = SEM_FAILED;
  }
  int value() {
    sem_t* s = sem_open(("/" + name_).c_str(), 0);
    int v = -1;
    sem_getvalue(s, &v);
    sem_close(s);
    return v;
  }
  static void settle() { usleep(50000); }  // a forked child reaches its wait
  std::string prefix_, name_;
  sem_t* sem_ = SEM_FAILED;
  std::vector<pid_t> children_;
};

TEST_F(PortLock, ALockWhoseHolderDiedIsGivenBack) {
  waitpid(holder(true), nullptr, 0);
  let_go();
  OrphanedPortLocks locks(prefix_);
  EXPECT_EQ(locks.note_taken(), 1u);
  EXPECT_EQ(locks.release(), std::vector<std::string>{name_});
  EXPECT_EQ(value(), 1);
  EXPECT_TRUE(locks.empty());
}

TEST_F(PortLock, AWaiterGetsTheLockOfADeadHolder) {
  waitpid(holder(true), nullptr, 0);
  const pid_t w = waiter();
  let_go();
  settle();
  OrphanedPortLocks locks(prefix_);
  ASSERT_EQ(locks.note_taken(), 1u);
  EXPECT_EQ(locks.release(), std::vector<std::string>{name_});
  int status = -1;
  waitpid(w, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the waiter got the lock";
}

TEST_F(PortLock, ALockHeldByALivingProcessIsLeftAlone) {
  holder(false);
  settle();  // the holder has it before the waiter comes
  const pid_t w = waiter();
  children_.push_back(w);
  let_go();
  settle();
  OrphanedPortLocks locks(prefix_);
  ASSERT_EQ(locks.note_taken(), 1u);
  EXPECT_TRUE(locks.release().empty());
  EXPECT_FALSE(locks.empty()) << "still watched: its holder may die yet";
  EXPECT_EQ(value(), 0);
  kill(children_.front(), SIGKILL);  // now it dies holding it
  waitpid(children_.front(), nullptr, 0);
  children_.erase(children_.begin());
  EXPECT_EQ(locks.release(), std::vector<std::string>{name_});
}

TEST_F(PortLock, AFreeLockIsNotNoted) {
  OrphanedPortLocks locks(prefix_);
  EXPECT_EQ(locks.note_taken(), 0u);
  EXPECT_TRUE(locks.release().empty());
  EXPECT_EQ(value(), 1);
}

// A port segment with a process-shared mutex in it, as Boost lays one out.
class PortSegment : public SharedMemoryDir {
 protected:
  void SetUp() override {
    SharedMemoryDir::SetUp();
    const auto file = dir_ / "testport7411";
    fd_ = open(file.c_str(), O_RDWR | O_CREAT, 0600);
    ASSERT_GE(fd_, 0);
    ASSERT_EQ(ftruncate(fd_, 4096), 0);
    map_ = mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
    ASSERT_NE(map_, MAP_FAILED);
    pthread_mutexattr_t attr;
    pthread_mutexattr_init(&attr);
    pthread_mutexattr_setpshared(&attr, PTHREAD_PROCESS_SHARED);
    pthread_mutex_init(mutex(), &attr);
    pthread_mutexattr_destroy(&attr);
  }
  void TearDown() override {
    munmap(map_, 4096);
    close(fd_);
    SharedMemoryDir::TearDown();
  }
  pthread_mutex_t* mutex() {
    return reinterpret_cast<pthread_mutex_t*>(static_cast<char*>(map_) + 64);
  }
  // A child that locks the mutex and dies (or lives on, holding it, until killed).
  pid_t locker(bool die) {
    const pid_t child = fork();
    if (child == 0) {
      pthread_mutex_lock(mutex());
      if (!die) pause();
      _exit(0);
    }
    usleep(50000);
    return child;
  }
  int fd_ = -1;
  void* map_ = nullptr;
};

TEST_F(PortSegment, AMutexWhoseOwnerDiedIsUnlocked) {
  waitpid(locker(true), nullptr, 0);
  ASSERT_EQ(pthread_mutex_trylock(mutex()), EBUSY) << "left locked by the dead child";
  EXPECT_EQ(release_mutexes_of_dead_threads(dir_, "testport"),
            std::vector<std::string>{"testport7411"});
  EXPECT_EQ(pthread_mutex_trylock(mutex()), 0);
  pthread_mutex_unlock(mutex());
}

TEST_F(PortSegment, AMutexOfALivingThreadIsLeftAlone) {
  const pid_t child = locker(false);
  EXPECT_TRUE(release_mutexes_of_dead_threads(dir_, "testport").empty());
  EXPECT_EQ(pthread_mutex_trylock(mutex()), EBUSY);
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  EXPECT_EQ(release_mutexes_of_dead_threads(dir_, "testport").size(), 1u) << "now it is dead";
  EXPECT_EQ(pthread_mutex_trylock(mutex()), 0);
  pthread_mutex_unlock(mutex());
}

TEST_F(PortSegment, AWaiterInAnotherProcessGetsTheMutex) {
  waitpid(locker(true), nullptr, 0);
  const pid_t waiter = fork();
  if (waiter == 0) {
    timespec deadline{};
    clock_gettime(CLOCK_REALTIME, &deadline);
    deadline.tv_sec += 10;
    _exit(pthread_mutex_timedlock(mutex(), &deadline) == 0 ? 0 : 1);
  }
  usleep(50000);
  EXPECT_EQ(release_mutexes_of_dead_threads(dir_, "testport").size(), 1u);
  int status = -1;
  waitpid(waiter, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "woken and given the mutex";
}

// Fast DDS's ring cells and allocator nodes hold small numbers; one shaped like a locked mutex of
// a dead thread, but with no user counted, is data and stays as it is.
TEST_F(PortSegment, WordsShapedLikeALockedMutexWithNoUserAreLeftAlone) {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_EQ(waitpid(child, nullptr, 0), child);
  const int cell[5] = {2, 0, child, 0, 128};  // lock, count, owner (dead), nusers, kind
  auto* at = static_cast<char*>(map_) + 1024;
  std::memcpy(at, cell, sizeof cell);
  EXPECT_TRUE(release_mutexes_of_dead_threads(dir_, "testport").empty());
  EXPECT_EQ(std::memcmp(at, cell, sizeof cell), 0);
}

TEST_F(PortSegment, OnlyPortSegmentsAreLookedAt) {
  waitpid(locker(true), nullptr, 0);
  fs::rename(dir_ / "testport7411", dir_ / "testport7411_el");
  EXPECT_TRUE(release_mutexes_of_dead_threads(dir_, "testport").empty()) << "a lock file";
  EXPECT_EQ(pthread_mutex_trylock(mutex()), EBUSY);
}

TEST(ParticipantIdentity, AnIdIsClaimedOnceUntilReleased) {
  const int domain = oscar::test::test_domain();
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
  const int domain = oscar::test::test_domain();
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
  DdsParticipant p(oscar::test::test_domain(), "own-port");
  EXPECT_EQ(ours(), before + 1);
  // It names that port, and maps its file under the name maps_current_port_file() looks for.
  const auto port = p.shared_memory_port();
  ASSERT_TRUE(port);
  EXPECT_EQ(internal::shared_memory_port_listener(*port), getpid());
  EXPECT_TRUE(maps_current_port_file(*port));
  EXPECT_FALSE(inodes_mapped_from(fmt::format("/dev/shm/fastrtps_port{}", *port)).empty());
}

}  // namespace
}  // namespace oscar
