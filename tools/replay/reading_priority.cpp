#include "reading_priority.hpp"

#include <unistd.h>

#include <thread>

namespace oscar::replay {

namespace {
bool set_policy(pid_t tid, int policy, const sched_param& param) {
  return sched_setscheduler(tid, policy, &param) == 0;
}

// Tried on a thread of its own: whether leaving SCHED_IDLE for `policy` again is allowed is the
// kernel's to say (capabilities, RLIMIT_NICE and RLIMIT_RTPRIO, a container's limits).
bool may_leave_idle(int policy, const sched_param& param) {
  bool may = false;
  std::thread probe(
      [&] { may = set_policy(0, SCHED_IDLE, sched_param{}) && set_policy(0, policy, param); });
  probe.join();
  return may;
}
}  // namespace

ReadingPriority::ReadingPriority() : tid_(gettid()), policy_(sched_getscheduler(0)) {
  sched_getparam(0, &param_);
  available_ = policy_ >= 0 && policy_ != SCHED_IDLE && may_leave_idle(policy_, param_);
}

ReadingPriority::~ReadingPriority() { normal(); }

void ReadingPriority::background() const {
  if (available_) set_policy(tid_, SCHED_IDLE, sched_param{});
}

void ReadingPriority::normal() const {
  if (available_) set_policy(tid_, policy_, param_);
}

}  // namespace oscar::replay
