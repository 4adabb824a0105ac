#pragma once
// Internal state of the Scheduler, shared by its translation units.

#include <string>
#include <vector>

#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm {

struct Scheduler::NodeState {
  NodeSpec spec;
  Trajectory committed;
  Trajectory working;  // committed with all open transactions applied
  std::vector<Job> committed_jobs;
  std::vector<Job> working_jobs;
  struct Lock {
    TransactionId tx;
    double lo, hi;
  };
  std::vector<Lock> locks;  // §4.2.7: trajectory sections changed by open transactions
};

// What one transaction changed on one node.
struct Scheduler::Change {
  double lo = 0, hi = 0;
  std::vector<std::string> added;
  std::vector<Job> removed;
};

// Precision limit of seed §5.3.1: doubles keep ~0.1 ns resolution up to this many seconds.
inline constexpr double kMaxAbsTime = 1e6;

void check_time(double t, const std::string& what);

}  // namespace oscar::swarm
