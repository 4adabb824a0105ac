#pragma once
// What killed modules leave behind in Fast DDS's shared memory and discovery, cleaned up by the
// monitor of their host (docs/boot.md, "Shared memory of killed modules").

#include <chrono>
#include <string>

#include "oscar/network.hpp"
#include "oscar/shared_memory.hpp"

namespace oscar {

class Janitor {
 public:
  using Clock = std::chrono::steady_clock;
  Janitor(int domain, NetworkConfig network);
  /// Right after one of the monitor's modules died: unlocks the port mutexes it held, announces
  /// its departure, and notes the port semaphores taken now (tick() gives back those it held).
  void after_death(const std::string& module);
  /// Call it often (the monitor does every 5 ms): gives back orphaned port semaphores for 2 s
  /// after a death, and sweeps the files of dead processes every second.
  void tick();

 private:
  int domain_;
  NetworkConfig network_;
  // What killed modules leave in /dev/shm goes once the others have let go of them (the 3 s
  // discovery lease of a participant, plus Fast DDS's 1-2 s port watchdog).
  DeadSharedMemorySweeper files_{std::chrono::seconds(5)};
  OrphanedPortLocks port_locks_;
  Clock::time_point next_sweep_ = Clock::now(), check_locks_until_ = Clock::now(),
                    next_lock_check_ = Clock::now();
};

}  // namespace oscar
