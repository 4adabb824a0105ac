#pragma once
/// @file Testing whole systems (docs/testing.md): boot a system file with `oscar boot` on a free
/// DDS domain, wait until its modules run or its channels carry cues, read cues, configure
/// modules with boot's authority, and shut it down leaving no process and no shared-memory file
/// behind, also when the test fails.

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <oscar/config.h>
#include <oscar/registry.h>

#include "oscar/cue.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/output.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar {
class ConfigClient;
class RegistryClient;
}  // namespace oscar

namespace oscar::testing {

/// Points $OSCAR_BIN_DIR at the folder of the running program if it is unset and that folder
/// holds oscar-boot: a tool or benchmark built beside the other programs boots systems with
/// them, not with whatever PATH finds.
void use_programs_beside_this_one();

/// A DDS domain that no system booted on this machine uses and no other test holds, reserved
/// for as long as the object lives (a lock file in $OSCAR_TEST_DOMAINS_DIR, default
/// /tmp/oscar/test-domains, that the kernel releases when the process ends, however it ends).
/// Parallel tests get different domains. It takes the highest free one (232 down to 1): systems
/// and tools use low domains.
class FreeDomain {
 public:
  /// The highest free domain, or the first free one from `first` down (then from 232 down):
  /// tests that start from a point of their own (e.g. of their pid) rarely get the domain the
  /// test before them had, where a process it left behind may still be ending.
  /// @throws std::runtime_error if every domain from 1 to 232 is taken.
  explicit FreeDomain(int first = 232);
  ~FreeDomain();
  FreeDomain(const FreeDomain&) = delete;
  FreeDomain& operator=(const FreeDomain&) = delete;
  int domain() const { return domain_; }

 private:
  int domain_ = -1;
  int fd_ = -1;
};

/// How SystemUnderTest boots its system.
struct BootOptions {
  int domain = -1;  ///< the DDS domain; -1: a FreeDomain of its own (the file's is ignored)
  std::chrono::seconds boot_timeout{30};  ///< boot's --timeout: until every module is announced
  std::string log_dir;  ///< where the processes write their output; default: a temporary folder
  /// boot's --keystore (docs/security.md); "": the file's `security: keystore:`, if any. With a
  /// keystore the test's own participant authenticates as `operator_boot`.
  std::string keystore{};
};

/// The watches a system handed out: their readers are closed when the system shuts down, before
/// the participant they read through goes (a watch may outlive the shutdown; it then gets no
/// more cues).
class WatchRegistry {
 public:
  void add(const void* watch, std::function<void()> close) {
    std::lock_guard lock(mutex_);
    if (closed_) {
      close();
    } else {
      watches_[watch] = std::move(close);
    }
  }
  void remove(const void* watch) {
    std::lock_guard lock(mutex_);
    watches_.erase(watch);
  }
  void close_all() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    for (auto& [watch, close] : watches_) close();
    watches_.clear();
  }

 private:
  std::mutex mutex_;
  bool closed_ = false;
  std::map<const void*, std::function<void()>> watches_;
};

/// Cues of one channel ("<kernel>/<channel>"), as they arrive. Reads best effort, so it matches
/// every producer; keeps the newest `capacity` cues until take() hands them out. With a
/// `registry`, its reader is closed when the registry's system shuts down.
template <CueType T>
class CueWatch {
 public:
  CueWatch(DdsParticipant& participant, const std::string& channel, std::size_t capacity = 1000,
           std::shared_ptr<WatchRegistry> registry = nullptr)
      : capacity_(capacity), registry_(std::move(registry)) {
    reader_ = std::make_unique<Reader>(participant, topics::cue(channel), reader_qos(capacity),
                                       [this](const T& cue, const auto&) {
                                         std::lock_guard lock(mutex_);
                                         cues_.push_back(cue);
                                         if (cues_.size() > capacity_) cues_.pop_front();
                                         arrived_.notify_all();
                                       });
    if (registry_) registry_->add(this, [this] { reader_.reset(); });
  }
  ~CueWatch() {
    if (registry_) registry_->remove(this);
    reader_.reset();
  }
  CueWatch(const CueWatch&) = delete;
  CueWatch& operator=(const CueWatch&) = delete;

  /// Waits until at least `count` cues are there (false if they are not within `timeout`).
  bool wait_for(std::size_t count, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return arrived_.wait_for(lock, timeout, [&] { return cues_.size() >= count; });
  }
  /// The cues that arrived since the last take(), oldest first.
  std::vector<T> take() {
    std::lock_guard lock(mutex_);
    std::vector<T> out(cues_.begin(), cues_.end());
    cues_.clear();
    return out;
  }
  std::size_t size() {
    std::lock_guard lock(mutex_);
    return cues_.size();
  }

 private:
  static eprosima::fastdds::dds::DataReaderQos reader_qos(std::size_t depth) {
    return qos::cue_reader(OutputOptions{.depth = depth, .reliable = false}, depth,
                           Reliability::kBestEffort);
  }

  std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<T> cues_;
  std::shared_ptr<WatchRegistry> registry_;
  // Not std::optional: GCC 12 then warns that the reader's pointer "may be used uninitialized"
  // in the destructor of some instantiations (a false positive that -Werror makes an error).
  using Reader = TopicReader<T, typename CueTraits<T>::PubSubType>;
  std::unique_ptr<Reader> reader_;  // uses the rest
};

/// A system booted by `oscar boot` for a test, on a domain of its own. The destructor shuts it
/// down (as Ctrl-C would), kills whatever did not stop in time, and removes the shared-memory
/// files of its processes. Its temporary folder (system logs, boot's output) is removed too,
/// unless the test has failed: then the failure messages name it.
class SystemUnderTest {
 public:
  /// Starts `oscar boot system_file`. The programs are taken from $OSCAR_BIN_DIR (which
  /// oscar_add_system_test sets), else from PATH.
  /// @throws std::runtime_error if oscar-boot is not found or cannot be started.
  explicit SystemUnderTest(const std::string& system_file, BootOptions options = {});
  ~SystemUnderTest();
  SystemUnderTest(const SystemUnderTest&) = delete;
  SystemUnderTest& operator=(const SystemUnderTest&) = delete;

  int domain() const { return domain_; }
  const std::string& file() const { return file_; }
  const std::string& log_dir() const { return log_dir_; }
  pid_t boot_pid() const { return boot_pid_; }
  /// What boot printed so far (its merged log of the system).
  std::string boot_output() const;
  /// Boot's exit code once it ended, waiting up to `timeout`; nullopt while it runs.
  std::optional<int> boot_exit_code(std::chrono::milliseconds timeout = {});
  /// The test's participant on the system's domain (loopback), for readers of its own.
  DdsParticipant& participant() { return *participant_; }
  RegistryClient& registry() { return *registry_; }

  /// The newest system state satisfying `pred` within `timeout`.
  std::optional<SystemState> wait_for(const std::function<bool(const SystemState&)>& pred,
                                      std::chrono::milliseconds timeout);
  /// Succeeds once the system runs and each of `modules` (all modules if empty) is running; the
  /// failure says what the system and boot reported.
  ::testing::AssertionResult wait_until_running(
      const std::vector<std::string>& modules = {},
      std::chrono::milliseconds timeout = std::chrono::seconds(60));
  /// Succeeds once each channel ("<kernel>/<channel>") has carried at least `count` cues since
  /// the call; their types are taken from discovery, so any registered cue type will do.
  ::testing::AssertionResult wait_for_cues(
      const std::vector<std::string>& channels, std::size_t count = 1,
      std::chrono::milliseconds timeout = std::chrono::seconds(30));
  /// Starts watching a channel's cues (read them with take() or wait_for()); after shut_down()
  /// the watch gets no more cues, and may still be read and destroyed.
  template <CueType T>
  std::unique_ptr<CueWatch<T>> watch(const std::string& channel, std::size_t capacity = 1000) {
    return std::make_unique<CueWatch<T>>(*participant_, channel, capacity, watches_);
  }
  /// The next `count` cues of a channel; fewer if they do not come within `timeout`.
  template <CueType T>
  std::vector<T> read_cues(const std::string& channel, std::size_t count,
                           std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    CueWatch<T> w(*participant_, channel, count);
    w.wait_for(count, timeout);
    return w.take();
  }

  /// Sends a configuration command to a module with boot's authority and returns the module's
  /// reply (check reply.ok() and reply.error()).
  /// @throws std::runtime_error if no module of that name answers within `timeout`.
  ConfigReply configure(const std::string& module, CommandKind kind, std::vector<std::string> args,
                        std::chrono::milliseconds timeout = std::chrono::seconds(5));

  /// Stops the system as Ctrl-C stops boot, waits up to `timeout`, then kills what is left and
  /// removes the shared-memory files of its processes. Returns boot's exit code (nullopt if boot
  /// had to be killed). Calling it again returns the same.
  std::optional<int> shut_down(std::chrono::milliseconds timeout = std::chrono::seconds(40));
  /// The /dev/shm files the system's processes were seen to own (noted whenever a wait
  /// succeeds and when the shutdown begins).
  const std::vector<std::string>& shared_memory_files() const { return shm_files_; }
  /// Processes of the system (boot, registry, monitors, modules) that are still alive.
  std::vector<pid_t> leftover_processes() const;
  /// Shared-memory files in /dev/shm of the system's processes that are still there.
  std::vector<std::string> leftover_shared_memory() const;

 private:
  void note_processes();
  std::string report() const;

  std::unique_ptr<FreeDomain> free_domain_;
  int domain_;
  std::string work_dir_, file_, log_dir_, boot_log_;
  pid_t boot_pid_ = -1;
  std::optional<int> boot_status_;
  std::optional<std::optional<int>> shut_down_;  ///< set once shut_down() ran: boot's exit code
  std::vector<pid_t> pids_;                      ///< every process of the system seen
  std::vector<std::string> shm_files_;           ///< /dev/shm files they had open
  std::unique_ptr<DdsParticipant> participant_;
  std::shared_ptr<WatchRegistry> watches_ = std::make_shared<WatchRegistry>();
  std::unique_ptr<RegistryClient> registry_;
  std::unique_ptr<ConfigClient> config_;
};

/// A GoogleTest fixture that boots a system in the test and shuts it down in TearDown(), failing
/// the test if a process or a shared-memory file of the system is left behind:
/// @code
/// using FuserSystem = oscar::testing::BootedSystem;
/// TEST_F(FuserSystem, FusesBothSources) {
///   boot();  // the SYSTEM file of oscar_add_system_test, or boot("path/to/system.yaml")
///   ASSERT_TRUE(wait_until_running({"fuser"}));
///   const auto cues = read_cues<oscar::Bool>("fuse/out", 3);
///   ...
/// }
/// @endcode
class BootedSystem : public ::testing::Test {
 protected:
  /// Boots `system_file`, or the file $OSCAR_TEST_SYSTEM names when it is empty (the SYSTEM of
  /// oscar_add_system_test).
  /// @throws std::invalid_argument if neither names a file.
  SystemUnderTest& boot(const std::string& system_file = "", BootOptions options = {});
  /// The booted system. @throws std::logic_error before boot().
  SystemUnderTest& system();

  ::testing::AssertionResult wait_until_running(
      const std::vector<std::string>& modules = {},
      std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
    return system().wait_until_running(modules, timeout);
  }
  ::testing::AssertionResult wait_for_cues(
      const std::vector<std::string>& channels, std::size_t count = 1,
      std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    return system().wait_for_cues(channels, count, timeout);
  }
  template <CueType T>
  std::vector<T> read_cues(const std::string& channel, std::size_t count,
                           std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    return system().read_cues<T>(channel, count, timeout);
  }
  template <CueType T>
  std::unique_ptr<CueWatch<T>> watch(const std::string& channel, std::size_t capacity = 1000) {
    return system().watch<T>(channel, capacity);
  }
  ConfigReply configure(const std::string& module, CommandKind kind,
                        std::vector<std::string> args) {
    return system().configure(module, kind, std::move(args));
  }
  std::optional<int> shut_down() { return system().shut_down(); }

  void TearDown() override;

 private:
  std::unique_ptr<SystemUnderTest> system_;
};

}  // namespace oscar::testing
