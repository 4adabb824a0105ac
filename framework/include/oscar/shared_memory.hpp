#pragma once
/// @file Housekeeping of Fast DDS's shared-memory transport files in /dev/shm.
///
/// A process killed with SIGKILL leaves its shared-memory segments and its listening port
/// behind (the lock file beside them is no longer held). They stay in /dev/shm, in memory, until
/// someone removes them; every monitor sweeps them a few seconds after their owner died. (No new
/// participant ever listens on a dead one's port: see framework/src/dds/participant_identity.hpp.)

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <sys/types.h>

namespace oscar {

/// Removes the shared-memory segments and ports of Fast DDS processes that are gone (those whose
/// lock file nobody holds), but only once they have been seen dead for `grace`: until then other
/// processes may still send to the dead participant (its discovery lease, plus Fast DDS's port
/// watchdog). Call sweep() now and then (the monitor does every second).
class DeadSharedMemorySweeper {
 public:
  using Clock = std::chrono::steady_clock;
  /// With `only`, it looks only at the files for whose name (in `dir`) it returns true: a test
  /// that shut its system down removes that system's files and no other's.
  explicit DeadSharedMemorySweeper(Clock::duration grace, std::filesystem::path dir = "/dev/shm",
                                   std::function<bool(const std::string&)> only = {});
  /// Notes what died since the last call and removes what has been dead for `grace`: segments
  /// and ports of dead owners, ports no reader owns (a sender created them while sending to a
  /// dead participant), and port semaphores whose port is gone (Fast DDS leaves them). A port
  /// whose number names a living listener (OSCAR's participants put their pid in it) stays, with
  /// its semaphore, whatever its lock file says. Returns how many of these files it removed.
  std::size_t sweep(Clock::time_point now = Clock::now());

 private:
  Clock::duration grace_;
  std::filesystem::path dir_;
  std::function<bool(const std::string&)> only_;
  std::map<std::string, Clock::time_point> dead_since_;  ///< lock file name -> first seen dead
};

/// What the processes of a system leave in `dir` once they are gone, removed at once: the
/// segments and ports of dead processes, the port semaphores Fast DDS leaves even at a clean exit,
/// and the participant id claims of `domain` that killed processes left. The registry and every
/// monitor call it as they exit, after their own participant is gone, so whichever exits last
/// leaves nothing behind, also when boot itself was killed. (Segments and ports do not name
/// their domain: those of another system's dead process go too, a little before its monitor
/// would remove them.) Returns how many files it removed.
std::size_t remove_files_of_dead_processes(int domain,
                                           const std::filesystem::path& dir = "/dev/shm");

/// Whether the port file `dir/fastrtps_port<port>` is still the one this process maps (its
/// participant listens there). A file another process removed (systemd-logind's RemoveIPC at the
/// end of the user's last session, an `rm`) or replaced leaves the listener waiting on a segment no
/// sender finds: every process that opens the port from then on creates another one, unheard.
/// True when this process maps no file of that name (nothing to judge).
bool maps_current_port_file(std::uint32_t port, const std::filesystem::path& dir = "/dev/shm");

/// Watches this process's own shared-memory port file (DdsParticipant::shared_memory_port()) as
/// maps_current_port_file() judges it. Fast DDS's own replacement of a port it found unhealthy
/// marks the old file and moves its listener to the new one within a second, so only a file that
/// stays lost for kLooks looks in a row counts.
class PortFileWatch {
 public:
  static constexpr int kLooks = 3;
  /// `port`: none without the shared-memory transport (nothing to watch).
  explicit PortFileWatch(std::optional<std::uint32_t> port, std::filesystem::path dir = "/dev/shm");
  /// One look (once a second): the port file's path once it has been lost for kLooks looks in a
  /// row, otherwise none.
  std::optional<std::string> lost();

 private:
  std::optional<std::uint32_t> port_;
  std::filesystem::path dir_;
  int lost_looks_ = 0;
  std::optional<ino_t> confirmed_;  // the port file's inode this process mapped at the last look
};

/// Releases the process-shared mutexes in Fast DDS's port segments (files in `dir` whose names
/// start with `prefix`) that a killed thread held.
///
/// Each port has mutexes of its own (its queue, its allocator), taken for a moment by everyone
/// who pushes into the port or opens it. A process killed in that moment leaves one locked, and
/// every later push into that port waits 1 s for it (Boost's lock timeout) with all of the
/// sender's traffic held up behind it, again and again: `oscar bench restart` saw the registry
/// and modules stall for seconds. A mutex whose owner thread no longer exists can never be
/// unlocked by its owner, so the monitor unlocks it in its place, as glibc would, right after
/// one of its modules died. (The owner is told from the mutex itself, so every process that
/// uses /dev/shm must share the monitor's pid namespace, as OSCAR's processes do.)
/// Returns the names of the files in which it released one.
std::vector<std::string> release_mutexes_of_dead_threads(
    const std::filesystem::path& dir = "/dev/shm", const std::string& prefix = "fastrtps_port");

/// Gives back the port locks that killed processes left taken.
///
/// Fast DDS opens a shared-memory port while holding a named POSIX semaphore
/// (`sem.fastrtps_port<N>_mutex`), for up to a third of a second while it checks the port's
/// listeners. A process killed meanwhile leaves it taken, and the next process to open that port
/// waits 2 s (Boost's lock timeout) before breaking it, sending nothing at all meanwhile. The
/// monitor notes which locks are taken when one of its modules dies, then calls release() for a
/// while: a lock that is taken while every process that has it open only waits for it (glibc
/// counts the waiters in the semaphore) has lost its holder, and is posted once.
class OrphanedPortLocks {
 public:
  /// Watches the semaphores whose names start with `prefix`.
  explicit OrphanedPortLocks(std::string prefix = "fastrtps_");
  /// Notes the locks taken now (call it right after a process died); returns how many.
  std::size_t note_taken();
  /// Posts the noted locks whose holder is gone and forgets those seen free; returns the names
  /// of the posted ones. Cheap when nothing is noted.
  std::vector<std::string> release();
  bool empty() const { return taken_.empty(); }

 private:
  std::string prefix_;
  std::vector<std::string> taken_;  ///< semaphore names (without "sem.")
};

}  // namespace oscar
