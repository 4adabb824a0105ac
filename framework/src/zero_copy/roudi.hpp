#pragma once
/// @file This process and the host's RouDi, iceoryx's shared-memory daemon (docs/zero_copy.md).

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>

namespace oscar::zero_copy {

/// True if a RouDi listens on this host (its socket /tmp/roudi takes a connection). Never blocks.
bool roudi_running();

/// Registers this process with the host's RouDi as `name` (once per process: after a success,
/// later calls return at once, whatever name they give). iceoryx itself would wait a minute for an
/// absent RouDi and then abort, so this asks first. A RouDi that goes away before it answers (one
/// that hung, killed by its monitor) ends the process at once (AwaitingRoudi; without
/// end_process_on_iceoryx_error(): exit code 1, the reason on stderr).
/// @throws std::invalid_argument for a name iceoryx cannot take (empty, too long, with '/').
/// @return nothing when registered, else why not (no RouDi, iox-roudi not installed).
std::optional<std::string> join_roudi(const std::string& name);

/// While it lives, this process waits for an answer of the RouDi it joined (before it joined: the
/// one it is registering with). iceoryx 2.0 waits for good, and a RouDi that hung and was killed
/// by its monitor never answers: from its own thread, this ends the process at once, as
/// end_process_on_iceoryx_error() says, as soon as that RouDi's socket is gone, another or takes
/// no message. Every request to RouDi is made under one: registration, a publisher or subscriber
/// port, a wait-set's condition variable, service discovery.
class AwaitingRoudi {
 public:
  /// `asking` completes "the RouDi this process ... went away", e.g. "asked for a publisher port".
  explicit AwaitingRoudi(std::string asking);
  AwaitingRoudi(const AwaitingRoudi&) = delete;
  AwaitingRoudi& operator=(const AwaitingRoudi&) = delete;

  /// The inode of the socket of the RouDi awaited.
  unsigned long socket_inode() const { return inode_; }

 private:
  void watch(std::stop_token stop);

  const std::string asking_;
  const std::string socket_;
  const unsigned long inode_;
  std::jthread thread_;  // last: stopped and joined first
};

/// iceoryx 2.0 aborts the process on a fatal or severe error of its own (most often: the RouDi this
/// process joined no longer answers a request for a publisher or subscriber). From this call on,
/// such an error is told through `say` (ending: true), naming it, and ends the process at once with
/// `exit_code`; a moderate one is told (ending: false) and the process goes on. A later call
/// replaces the earlier.
void end_process_on_iceoryx_error(int exit_code,
                                  std::function<void(const std::string& what, bool ending)> say);

/// Watches that the RouDi this process joined is still the host's. A RouDi started after the
/// joined one died makes a management segment of its own (`/dev/shm/iceoryx_mgmt`, a new file),
/// and iceoryx 2.0 cannot move a process over: it would publish and wait where no process started
/// since looks. Calls `gone` once, on the watch's thread, when the segment this process mapped is
/// no longer the one of that name (and the new RouDi listens, so that a process started again
/// joins it), or when that name is gone. A RouDi killed and not replaced leaves its segment: the
/// processes that joined it go on reaching each other, and nothing is called.
class RoudiWatch {
 public:
  /// Needs join_roudi() first. @throws std::runtime_error if this process maps no segment.
  explicit RoudiWatch(std::function<void(const std::string& why)> gone,
                      std::chrono::milliseconds period = std::chrono::milliseconds(250));
  ~RoudiWatch();
  RoudiWatch(const RoudiWatch&) = delete;
  RoudiWatch& operator=(const RoudiWatch&) = delete;

 private:
  void watch();

  const std::function<void(const std::string&)> gone_;
  const std::chrono::milliseconds period_;
  unsigned long joined_inode_ = 0;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

/// True if a process of this host's RouDi offers `topic` with cues of `type_name` (an iceoryx
/// publisher of its service). Needs join_roudi() first.
bool offered_on_this_host(const std::string& topic, const std::string& type_name);

/// The iceoryx topic of the DDS topic `topic` in DDS domain `domain`: systems of other domains
/// on the same host never meet.
std::string zero_copy_topic(int domain, const std::string& topic);

}  // namespace oscar::zero_copy
