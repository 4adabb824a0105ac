#pragma once
/// @file Housekeeping of Fast DDS's shared-memory transport files in /dev/shm.
///
/// A process killed with SIGKILL leaves its shared-memory segments and its listening port
/// behind (the lock file beside them is no longer held). They stay in /dev/shm, in memory, until
/// someone removes them; every monitor sweeps them a few seconds after their owner died. (No new
/// participant ever listens on a dead one's port: see framework/src/participant_identity.hpp.)

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>

namespace oscar {

/// Removes the shared-memory segments and ports of Fast DDS processes that are gone (those whose
/// lock file nobody holds), but only once they have been seen dead for `grace`: until then other
/// processes may still send to the dead participant (its discovery lease, plus Fast DDS's port
/// watchdog). Call sweep() now and then (the monitor does every second).
class DeadSharedMemorySweeper {
 public:
  using Clock = std::chrono::steady_clock;
  explicit DeadSharedMemorySweeper(Clock::duration grace, std::filesystem::path dir = "/dev/shm");
  /// Notes what died since the last call and removes what has been dead for `grace`. Returns how
  /// many segments and ports it removed.
  std::size_t sweep(Clock::time_point now = Clock::now());

 private:
  Clock::duration grace_;
  std::filesystem::path dir_;
  std::map<std::string, Clock::time_point> dead_since_;  ///< lock file name -> first seen dead
};

}  // namespace oscar
