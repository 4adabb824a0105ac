#include "reading_priority.hpp"

#include <sched.h>
#include <unistd.h>

#include <thread>

namespace oscar::replay {

namespace {
bool set_policy(pid_t tid, int policy) {
  sched_param none{};
  return sched_setscheduler(tid, policy, &none) == 0;
}

// Tried on a thread of its own: whether leaving SCHED_IDLE is allowed is the kernel's to say
// (capabilities, RLIMIT_NICE, a container's limits).
bool may_leave_idle() {
  bool may = false;
  std::thread probe([&may] { may = set_policy(0, SCHED_IDLE) && set_policy(0, SCHED_OTHER); });
  probe.join();
  return may;
}
}  // namespace

ReadingPriority::ReadingPriority() : tid_(gettid()), available_(may_leave_idle()) {}

ReadingPriority::~ReadingPriority() { normal(); }

void ReadingPriority::background() const {
  if (available_) set_policy(tid_, SCHED_IDLE);
}

void ReadingPriority::normal() const {
  if (available_) set_policy(tid_, SCHED_OTHER);
}

}  // namespace oscar::replay
