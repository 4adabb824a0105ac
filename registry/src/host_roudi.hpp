#pragma once
// The monitor's keeper of its host's RouDi, iceoryx's shared-memory daemon that carries plain
// cues between the host's processes without copies (docs/zero_copy.md, "RouDi per host").

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "oscar/registry/supervisor.hpp"

namespace oscar {

class HostRoudi {
 public:
  using Clock = std::chrono::steady_clock;

  /// Writes RouDi's configuration, `chunks` of each plain cue type, to `<log_dir>/roudi.toml`;
  /// RouDi's output goes to `<log_dir>/iox-roudi.log`. Starts nothing yet (tick() does).
  HostRoudi(std::uint32_t chunks, const std::string& log_dir);
  /// Stops the RouDi it started (call it after the host's modules have stopped).
  ~HostRoudi();
  HostRoudi(const HostRoudi&) = delete;
  HostRoudi& operator=(const HostRoudi&) = delete;

  /// Call it often (the monitor does every 5 ms; it looks every 100 ms): starts a RouDi when
  /// none listens on this host, and says when one ended. A RouDi another process started (an
  /// earlier monitor's, another system's) is used, not doubled; when it goes, this one starts
  /// its own. A RouDi that ends within 5 s of its start is started again after a pause that
  /// doubles from 0.5 s to 8 s; one that ran longer, at once. A RouDi it started that hangs
  /// (its discovery thread, which wakes every 100 ms, has not run for `kHungAfter`) is killed,
  /// and so started again.
  void tick(Clock::time_point now = Clock::now());

  /// How long RouDi's discovery thread may not run before it counts as hung. iceoryx 2.0 hangs
  /// for good when a process dies holding the lock of one of its publishers (iceoryx issue 1711:
  /// a producer killed while it publishes, and another process asking for a port of the topic).
  static constexpr std::chrono::seconds kHungAfter{3};

  /// True once, as of the last tick(), a RouDi listens on this host or starting one failed.
  /// Modules started before that begin on DDS and move to shared memory only once one listens.
  bool settled() const { return listening_said_ || foreign_said_ || failure_said_; }
  /// How long a monitor holds its first launches back until settled().
  static constexpr std::chrono::seconds kSettlePatience{5};

  /// How many RouDis it has started so far (a restart invalidates what processes that joined the
  /// one before hold: iceoryx 2.0 cannot re-register them).
  unsigned started() const { return started_; }
  /// The pid of the RouDi it started, if that one runs (0 otherwise).
  pid_t pid() const;
  const std::string& config_path() const { return config_path_; }

 private:
  void start(Clock::time_point now);
  /// Kills the RouDi it started if its discovery thread has not run for kHungAfter.
  void kill_if_hung(Clock::time_point now);

  Supervisor processes_;
  std::string config_path_;
  unsigned started_ = 0;
  Clock::time_point started_at_{}, next_look_{}, next_start_{};
  std::chrono::milliseconds pause_{0};
  bool listening_said_ = false;  // "RouDi runs" logged for the current RouDi
  bool foreign_said_ = false;    // "uses the RouDi already running" logged
  bool failure_said_ = false;    // why it cannot start RouDi, logged
  // The discovery thread's count of sleeps, and since when it has not changed.
  std::optional<unsigned long long> discovery_sleeps_;
  Clock::time_point discovery_slept_at_{};
};

}  // namespace oscar
