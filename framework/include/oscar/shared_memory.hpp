#pragma once
/// @file Housekeeping of Fast DDS's shared-memory transport files in /dev/shm.
///
/// A process killed with SIGKILL leaves its shared-memory segments and its listening port
/// behind ("zombies": the lock file beside them is no longer held). Two things follow, and this
/// file handles both:
/// - A participant that takes over the dead one's participant id would listen on the same port,
///   while the other processes still push into their mapping of the old port until Fast DDS's
///   watchdog notices, 1–2 s later. DdsParticipant therefore avoids ids whose port is a zombie.
/// - The files stay in /dev/shm (memory) until someone removes them; every monitor sweeps them
///   a few seconds after their owner died.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

namespace oscar {

/// True if the shared-memory port `port` (a participant's user unicast port) was left behind by
/// a process that died without closing it.
bool shared_memory_port_is_zombie(std::uint32_t port,
                                  const std::filesystem::path& dir = "/dev/shm");

/// Removes the shared-memory segments and ports of Fast DDS processes that are gone (those whose
/// lock file nobody holds), but only once they have been seen dead for `grace`: other processes
/// still send into a dead port until they have let go of its participant (its discovery lease,
/// plus Fast DDS's port watchdog), and a new participant must not open a fresh port under that
/// id before. Call sweep() now and then (the monitor does every second).
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
