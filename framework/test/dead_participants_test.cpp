#include "oscar/dead_participants.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>

#include "dds/participant_identity.hpp"  // framework/src
#include "oscar/dds_participant.hpp"
#include "process.hpp"  // tests/common

namespace oscar {
namespace {
using namespace std::chrono_literals;
using eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;

// Notes how other participants came and went.
class Discovery : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                ParticipantDiscoveryInfo&& info) override {
    std::lock_guard lock(mutex_);
    events_.emplace_back(info.info.m_guid.guidPrefix, info.status);
    changed_.notify_all();
  }
  // Waits for the event after the `seen` first ones; returns its status.
  std::optional<ParticipantDiscoveryInfo::DISCOVERY_STATUS> next(std::size_t& seen,
                                                                 std::chrono::seconds timeout) {
    std::unique_lock lock(mutex_);
    if (!changed_.wait_for(lock, timeout, [&] { return events_.size() > seen; })) return {};
    return events_[seen++].second;
  }
  eprosima::fastrtps::rtps::GuidPrefix_t prefix(std::size_t i) {
    std::lock_guard lock(mutex_);
    return events_.at(i).first;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<
      std::pair<eprosima::fastrtps::rtps::GuidPrefix_t, ParticipantDiscoveryInfo::DISCOVERY_STATUS>>
      events_;
};

// A participant in a child process, killed with SIGKILL: the announcement made in its name makes
// the others remove it as one that left (REMOVED), not drop it when its lease ends (DROPPED).
TEST(DeadParticipants, TheDepartureOfAKilledParticipantIsAnnouncedInItsName) {
  const int domain = oscar::test::test_domain();
  int go[2], ready[2];
  ASSERT_EQ(pipe(go), 0);
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();  // before this process has any DDS thread
  if (child == 0) {
    close(go[1]);
    char byte = 0;
    // Made only once the observer listens: discovery may see it before any listener is set.
    if (read(go[0], &byte, 1) != 1) _exit(1);
    DdsParticipant doomed(domain, "doomed");
    // Its prefix is in its claim once the constructor returns; discovery can see it before.
    if (write(ready[1], "r", 1) != 1) _exit(1);
    pause();
    _exit(0);
  }
  close(go[0]);
  close(ready[1]);
  // Whatever fails below, the child goes: alive, it would hold the test's output open.
  struct Reaper {
    pid_t pid;
    ~Reaper() {
      if (pid > 0 && kill(pid, SIGKILL) == 0) waitpid(pid, nullptr, 0);
    }
  } reaper{child};
  Discovery discovery;
  DdsParticipant observer(domain, "observer");
  observer.get().set_listener(&discovery, eprosima::fastdds::dds::StatusMask::none());
  ASSERT_EQ(write(go[1], "g", 1), 1);
  close(go[1]);
  std::size_t seen = 0;
  ASSERT_EQ(discovery.next(seen, 20s), ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT);
  const auto doomed = discovery.prefix(0);
  std::ostringstream expected;
  expected << doomed;
  EXPECT_TRUE(announce_killed_participants(domain, {}).empty()) << "nobody died yet";
  char byte = 0;
  ASSERT_EQ(read(ready[0], &byte, 1), 1) << "the child's participant was not made";
  close(ready[0]);

  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  reaper.pid = 0;
  const auto announced = announce_killed_participants(domain, {});
  ASSERT_EQ(announced.size(), 1u);
  EXPECT_EQ(announced[0], expected.str()) << "the killed one's prefix, from its claim";
  EXPECT_EQ(discovery.next(seen, 20s), ParticipantDiscoveryInfo::REMOVED_PARTICIPANT)
      << "removed on the announcement, not dropped at the end of its lease";
  EXPECT_TRUE(announce_killed_participants(domain, {}).empty()) << "announced once";
  observer.get().set_listener(nullptr);
}

}  // namespace
}  // namespace oscar
