#pragma once
// Internal state of the Scheduler, shared by its translation units.

#include <map>
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
    Section section;
  };
  std::vector<Lock> locks;  // §4.2.7: trajectory sections changed by open transactions
  bool broken = false;      // broke down: an obstacle that takes no jobs
};

// What one transaction changed on one node: disjoint sections of its trajectory (commit and abort
// splice exactly these, never what lies between them) and the jobs it added and removed.
struct Scheduler::Change {
  std::vector<Section> sections;
  std::vector<std::string> added;
  std::vector<Job> removed;
};

// An open transaction (§4.2.7). An atomic one (a job set, a job moved between nodes) commits or
// aborts as a whole: its changes on one node mean nothing without those on the others.
struct Scheduler::Transaction {
  std::map<std::string, Change> changes;  // by node id
  bool atomic = false;
  std::string what;  // for messages: "periodic set P1, P2"
  // unschedule_set: members a broken-down node lost that leave their set when this commits
  std::vector<std::string> lost_given_up;
  // change_world: set members it removes, lost (as after break_down) when this commits
  std::vector<Job> displaced_members;
};

// A periodic or dependent set (§4.2.3, §4.2.4): its members are unscheduled together or not at all.
// What ties them together is kept, so a member a broken-down node lost is placed again within it.
struct Scheduler::JobSet {
  std::string what;  // "periodic set P1, P2, P3"
  std::vector<std::string> ids = {};
  std::map<std::string, std::vector<std::string>> depends = {};  // dependent: what each waits for
  bool same_location = false;  // periodic set: every repetition at one place
};

// Precision limit of seed §5.3.1: doubles keep ~0.1 ns resolution up to this many seconds.
inline constexpr double kMaxAbsTime = 1e6;

void check_time(double t, const std::string& what);

/// Up to `count` locations of the area minus the obstacles, spread breadth first over ever smaller
/// rectangles (seed Anhang A.1, SAMPLE_LOCATIONS); none if nothing of the area is free.
std::vector<Point> sample_locations(const Polygon& area, const std::vector<Polygon>& obstacles,
                                    int count);

}  // namespace oscar::swarm
