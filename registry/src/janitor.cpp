#include "janitor.hpp"

#include <spdlog/spdlog.h>

#include "oscar/dead_participants.hpp"

namespace oscar {

Janitor::Janitor(int domain, NetworkConfig network)
    : domain_(domain), network_(std::move(network)) {}

void Janitor::after_death(const std::string& module) {
  for (const auto& port : release_mutexes_of_dead_threads()) {
    spdlog::warn("unlocked {}, whose lock a killed process held", port);
  }
  for (const auto& p : announce_killed_participants(domain_, network_)) {
    spdlog::info("announced the departure of participant {} of {}", p, module);
  }
  port_locks_.note_taken();
  check_locks_until_ = Clock::now() + std::chrono::seconds(2);
}

void Janitor::tick() {
  const auto now = Clock::now();
  if (!port_locks_.empty() && now >= next_lock_check_) {
    next_lock_check_ = now + std::chrono::milliseconds(20);
    for (const auto& lock : port_locks_.release()) {
      spdlog::warn("gave back {}, which a killed process held (Fast DDS would wait 2 s for it)",
                   lock);
    }
    if (now > check_locks_until_) port_locks_ = OrphanedPortLocks();
  }
  if (now >= next_sweep_) {
    if (const auto n = files_.sweep(); n > 0) {
      spdlog::info("removed {} shared-memory files of dead processes", n);
    }
    next_sweep_ = now + std::chrono::seconds(1);
  }
}

}  // namespace oscar
