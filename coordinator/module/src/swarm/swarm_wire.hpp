#pragma once
// Between the swarm's IDL (idl/oscar/swarm.idl) and the planner's types: times on the wire are
// the system clock in ns, the planner counts seconds from the service's epoch (it keeps sub-ns
// precision only within ±1e6 s, seed 002 §5.3.1).

#include <cstdint>
#include <string>
#include <vector>

#include <oscar/swarm.h>

#include "oscar/swarm/scheduler.hpp"

namespace oscar::coordinator::swarm_wire {

/// The planner's clock: seconds since `epoch_ns`.
struct Clock {
  std::int64_t epoch_ns = 0;
  double seconds(std::int64_t ns) const { return static_cast<double>(ns - epoch_ns) * 1e-9; }
  std::int64_t ns(double seconds) const;
};

/// @throws std::invalid_argument naming the job and the rule (area, window, duration).
swarm::JobSpec job_spec(const SwarmJobSpec& wire, const Clock& clock);
/// The other way round: a job's specification as a request carries it.
SwarmJobSpec wire_job_spec(const swarm::JobSpec& spec, const Clock& clock);

/// What a request asks the planner, as a call on `scheduler`.
/// @throws std::invalid_argument on a request that is not well-formed, or as the planner throws.
swarm::ScheduleResult apply(swarm::Scheduler& scheduler, const SwarmRequest& request,
                            const Clock& clock);

SwarmPlacedJob placed(const swarm::Job& job, const Clock& clock);

/// The proposal for one robot of a transaction: its sections as the working trajectory has them.
Trajectory proposal(const swarm::Scheduler& scheduler, swarm::TransactionId tx,
                    const swarm::Scheduler::NodeChange& change, const Clock& clock);

/// The committed plan as `oscar swarm snapshot` draws it: the world, each robot's committed
/// trajectory (a trajectory that stays at its end for good ends at its last move), the committed
/// jobs that end after the present.
SwarmPlan plan(const swarm::Scheduler& scheduler, const Clock& clock);

/// The committed jobs that end after the present.
std::vector<SwarmPlacedJob> upcoming_jobs(const swarm::Scheduler& scheduler, const Clock& clock);

/// What a robot has committed, as a coordinator that restarted takes it over
/// (Scheduler::add_node with a committed plan).
struct CommittedPlan {
  swarm::Trajectory trajectory;  ///< from the robot's time of answering on
  std::vector<swarm::Job> jobs;  ///< by start
  /// Nothing to take over: it stands for good and has no job (an idle robot).
  bool idle() const;
};

/// The side of the square a job taken over is specified in, around its place (m): a robot tells
/// where it works a job, not the area it was asked for.
inline constexpr double kTakenOverJobArea = 0.1;

/// A robot's answer to command `committed` (oscar/swarm_yaml.hpp: a Trajectory with one
/// open-ended section from the robot's now, and its jobs not yet done in jobs_added) in the
/// planner's terms. Each job's spec is its place as a square of kTakenOverJobArea, its window
/// and its duration.
/// @throws std::invalid_argument naming the rule: text that is no Trajectory, an answer for
/// another robot, not exactly one open-ended section with waypoints, times that decrease, a job
/// that ends before it starts.
CommittedPlan committed_plan(const std::string& robot, const std::string& answer,
                             const Clock& clock);

/// "schedule", "periodic" ... for messages.
std::string kind_name(SwarmRequestKind kind);

}  // namespace oscar::coordinator::swarm_wire
