#pragma once
/// @file The space-time scheduler (seed 002 ch. 4, Anhang A).

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "oscar/swarm/job.hpp"
#include "oscar/swarm/load.hpp"
#include "oscar/swarm/schedule_result.hpp"
#include "oscar/swarm/spatial_path_finder.hpp"
#include "oscar/swarm/trajectory.hpp"
#include "oscar/swarm/trajectory_planner.hpp"
#include "oscar/swarm/world.hpp"

namespace oscar::swarm {

class DubinsPathFinder;

/// Scheduler settings (seed §4.2.1, §4.2.4, §4.3.4).
struct SchedulerSettings {
  double present = 0;            ///< present time (s)
  double frozen_horizon = 0;     ///< t_FH = present + frozen_horizon (§4.2.1)
  double dependency_margin = 0;  ///< d_m of eq. 4.10/4.11
  int location_samples = 10;     ///< locations tried per job (§4.2.1, Ort)
  double wait_threshold = 0;     ///< d_th of §4.3.4
  unsigned seed = 1;             ///< seed of the random path planner (OMPL's, with each leg)
};

/// A periodic job set (seed §4.2.3): job i starts within [start + i·period, start + (i+1)·period -
/// d].
struct PeriodicSpec {
  std::vector<std::string> ids;
  Polygon area;
  bool same_location = true;
  double start = 0;
  double period = 0;
  double duration = 0;
};

/// Dependent jobs (seed §4.2.4): `depends[c]` lists the jobs c waits for.
struct DependentSpec {
  std::vector<JobSpec> jobs;
  std::map<std::string, std::vector<std::string>> depends;
};

/// An idle slot (pause) of a node that meets conditions 4.2–4.4 for a location (seed §4.2.1).
struct Slot {
  std::string node;
  std::size_t index = 0;  ///< position of the new job in the node's job list
  double t1 = 0;          ///< pause start, moved to the frozen horizon if earlier
  double t2 = 0;          ///< pause end (kForever after the last job)
  Point from;             ///< where the node is at t1
  Point at;               ///< the job location
  double detour = 0;      ///< Δs of eq. 4.5 (s1 + s2 - s12)
};

/// What Scheduler::change_world did.
struct WorldChange {
  bool ok = false;
  std::string reason;              ///< why the change was refused (the world stayed as it was)
  TransactionId transaction = 0;   ///< the open transaction re-planning nodes; 0: none had to
  std::vector<std::string> nodes;  ///< the nodes it re-plans
  std::vector<Job> displaced;      ///< jobs those nodes cannot keep in the changed world
};

/// Schedules jobs onto nodes and plans their trajectories (seed ch. 4): location sampling, idle
/// slots by conditions 4.2–4.4, least detour first (4.5), path-velocity decomposition (§4.3),
/// periodic (A.2) and dependent (A.3) sets atomically, and transactions (§4.2.7) whose alternative
/// trajectories count as obstacles and which lock the trajectory sections they change.
/// Bad input throws std::invalid_argument; infeasible jobs are ScheduleResult values.
class Scheduler {
 public:
  /// @throws std::invalid_argument on non-finite or out-of-range settings.
  Scheduler(World world, SchedulerSettings settings);
  ~Scheduler();
  Scheduler(Scheduler&&) noexcept;
  Scheduler& operator=(Scheduler&&) noexcept;

  /// Adds a node idle at its start (seed §5.2 addNode). If a moving obstacle or another node will
  /// cross the start later, the node's trajectory steps aside in time (README, "Idle nodes").
  /// @throws std::invalid_argument on a duplicate id, bad numbers, a start inside an obstacle or
  /// too close to another node, or no free place to step aside to.
  void add_node(const NodeSpec& spec);
  /// Adds a node that already drives a committed trajectory and works committed jobs (a
  /// coordinator that restarted takes over what its predecessor committed): they become the
  /// node's committed schedule as they are, so other nodes avoid them and new jobs of the node go
  /// into its pauses like into any committed schedule. The node is at (spec.x, spec.y) at spec.t
  /// (its first pause starts there); after the trajectory's last waypoint it stays there for good.
  /// The jobs are single jobs (set memberships are not known); each carries its spec for a later
  /// re-placement (break_down).
  /// @throws std::invalid_argument as add_node(spec), or naming the node, the job and the rule:
  /// the trajectory must hold spec.t (start at or before it) and have the node within 1 cm of
  /// (spec.x, spec.y) then; each job must be valid as a new job (its id unused), not end before
  /// spec.t, lie within its window, keep the node within 1 cm of its place while it lasts, and
  /// not overlap another.
  void add_node(const NodeSpec& spec, const Trajectory& committed, std::vector<Job> jobs);

  /// Schedules one job in a new transaction (seed §4.2.1, A.4).
  /// @throws std::invalid_argument on an invalid spec or an id already in use.
  ScheduleResult schedule(const JobSpec& spec);
  /// Schedules a periodic set, all or nothing (§4.2.3, A.2).
  ScheduleResult schedule(const PeriodicSpec& spec);
  /// Schedules dependent jobs, all or nothing, earliest implicit deadline first (§4.2.4, A.3).
  /// @throws std::invalid_argument on unknown ids or a cycle.
  ScheduleResult schedule(const DependentSpec& spec);
  /// Removes a job and re-plans the trajectory around the gap (§4.2.5). A member of a periodic or
  /// dependent set is refused (the set would lose its guarantee): use unschedule_set.
  /// @throws std::invalid_argument on an unknown id.
  ScheduleResult unschedule(const std::string& job_id);
  /// Unschedules the members of the set `member_id` belongs to that start after the frozen
  /// horizon, in one atomic transaction; members already started stay (§4.2.5 for a set). Members
  /// a broken-down node lost (see break_down) leave the set when the transaction commits.
  /// @throws std::invalid_argument on an unknown id or a job that belongs to no set.
  ScheduleResult unschedule_set(const std::string& member_id);
  /// Places again, in one atomic transaction, the members of the set `member_id` belongs to that
  /// a broken-down node lost (those no open transaction places already), so that the set keeps
  /// its guarantee with its other members as they are placed now: a dependent member within its
  /// implicit window given their starts (eq. 4.10/4.11: after the members it waits for have ended,
  /// before those waiting for it start, margin included), a periodic one within its repetition's
  /// window and, for a same-location set, at the set's place; dependencies first, the earliest
  /// implicit deadline first (A.3). Once committed they are members as before. All or nothing: on
  /// failure the reason names the member that fits nowhere, the schedule is unchanged and the
  /// members stay lost (give the set up with unschedule_set).
  /// @throws std::invalid_argument on an id of no set, or a set with no lost member to place.
  ScheduleResult schedule_lost(const std::string& member_id);
  /// The set a job belongs to, as messages name it ("dependent set A, B"); empty for a job of no
  /// set or an unknown id.
  std::string set_name(const std::string& job_id) const;
  /// Removes a job without re-planning (§4.2.5).
  /// @throws std::invalid_argument on an unknown id.
  ScheduleResult remove_job(const std::string& job_id);
  /// Unschedules and schedules again atomically (§4.2.6). Set members are refused as by unschedule.
  ScheduleResult reschedule(const JobSpec& spec);

  /// Commits a transaction, wholly or for one node (§4.2.7). An atomic transaction (a job set, or
  /// a job moved between nodes) that changes several nodes commits only as a whole.
  /// @throws std::invalid_argument on an unknown transaction or node, or one node of an atomic
  /// transaction that changes several.
  void commit(TransactionId id, const std::string& node = "");
  /// Aborts a transaction, wholly or for one node (§4.2.7); atomic ones only as a whole.
  /// @throws std::invalid_argument as commit.
  void abort(TransactionId id, const std::string& node = "");
  /// The open transactions, oldest first.
  std::vector<TransactionId> open_transactions() const;

  /// The slots of all nodes meeting conditions 4.2–4.4 for `spec` at `at`, least detour first
  /// (eq. 4.5), excluding slots locked by transactions other than `tx` (§4.2.7).
  std::vector<Slot> qualifying_slots(const JobSpec& spec, const Point& at,
                                     TransactionId tx = 0) const;

  /// The world changes while the swarm runs: obstacles are added or removed (beyond seed §4.1,
  /// whose world is fixed). From the frozen horizon on the schedule lives in the new world: every
  /// node whose trajectory after t_FH runs into it is planned again, all in one atomic
  /// transaction — from where it is at t_FH, each of its jobs at its place and start where it
  /// can still get there around the new obstacles, then idling as after any last job. The jobs
  /// it cannot keep are removed and returned in `displaced`, to be placed again once the
  /// transaction commits: a single job with schedule, a member of a periodic or dependent set
  /// (which then is lost, as after break_down) with schedule_lost. Nothing before t_FH changes,
  /// so a change that a node runs into before t_FH, or that covers the place of a job worked
  /// then, is refused (`ok` false, the reason names the node and the time) and the world stays
  /// as it was. If the transaction aborts, the world stays changed: call change_world again with
  /// the same world to plan the nodes again, or with the old one to go back.
  /// @throws std::invalid_argument on an invalid world (as the constructor) or while a
  /// transaction is open (the change must not meet half-applied plans).
  WorldChange change_world(World world);

  /// Removes a node that has no job left to do (seed §4.1, §5.5.2): every job of it ends before the
  /// present and no open transaction changes it. From then on it is no obstacle to anyone (§4.1:
  /// removed robots vanish).
  /// @throws std::invalid_argument on an unknown node, unfinished jobs or an open transaction.
  void remove_node(const std::string& id);
  /// A node that broke down at time `t` at `where` (beyond seed §4.1, whose robots never fail):
  /// it stands there for good and takes no more jobs, but stays an obstacle to the others. Its
  /// jobs that do not end by `t` are removed and returned, to be scheduled elsewhere: a single job
  /// with schedule, a member of a periodic or dependent set with schedule_lost. Such a member
  /// stays in its set, lost, until schedule_lost places it again or unschedule_set gives the set
  /// up; meanwhile its id stays in use.
  /// @throws std::invalid_argument on an unknown node, one already broken down, `t` before the
  /// present, or an open transaction that changes the node (abort it first).
  std::vector<Job> break_down(const std::string& id, double t, const Point& where);
  /// True once break_down took the node out of planning.
  bool broken_down(const std::string& id) const;
  /// Nodes that new jobs must not go to until this is called again (a robot that refused a
  /// request, when the request is planned again); they stay obstacles. Unknown ids are ignored.
  void set_excluded(std::set<std::string> nodes) { excluded_ = std::move(nodes); }

  /// What an open transaction changes on one node: the sections of its trajectory (their times;
  /// the waypoints are the working trajectory's there) and its jobs added and removed.
  struct NodeChange {
    std::string node;
    std::vector<std::pair<double, double>> sections;
    std::vector<Job> added;
    std::vector<std::string> removed;
  };
  /// The changes of an open transaction, by node.
  /// @throws std::invalid_argument on an unknown or finished transaction.
  std::vector<NodeChange> changes(TransactionId id) const;

  /// Forgets what lies before `t` (at most the present): jobs that ended before it and the
  /// trajectories' waypoints before it (each keeps its place at t). A long-running swarm calls it
  /// now and then, so planning does not slow down with its history.
  /// @throws std::invalid_argument if t is after the present.
  void forget_before(double t);

  /// Moves the present forward (§4.2.1).
  /// @throws std::invalid_argument if t is before the present or not finite.
  void set_present(double t);
  double present() const { return settings_.present; }
  /// t_FH: nothing before it changes.
  double frozen_horizon_time() const { return settings_.present + settings_.frozen_horizon; }

  /// The node ids in the order added.
  std::vector<std::string> node_ids() const;
  const NodeSpec& node(const std::string& id) const;
  /// The committed trajectory, or the working one with all open transactions applied.
  const Trajectory& trajectory(const std::string& node, bool committed = true) const;
  /// The committed (or working) jobs of a node, by start time.
  const std::vector<Job>& jobs(const std::string& node, bool committed = true) const;
  /// Load figures of a node's committed schedule over [t0, t1] (seed §4.4).
  /// @throws std::invalid_argument on an unknown node or an empty interval.
  Load load(const std::string& node, double t0, double t1) const;
  const World& world() const { return world_; }
  const SchedulerSettings& settings() const { return settings_; }

 private:
  struct Section {
    double lo = 0, hi = 0;
  };
  struct NodeState;
  struct Change;
  struct Transaction;
  struct JobSet;
  NodeState& state(const std::string& id);
  const NodeState& state(const std::string& id) const;
  TransactionId open_transaction(bool atomic = false, std::string what = "");
  void check_node_spec(const NodeSpec& spec) const;
  static void check_world(const World& world);
  std::optional<double> runs_into_world(const NodeState& n, double lo, double hi) const;
  bool replan_in_world(NodeState& n, TransactionId tx, std::vector<Job>& displaced,
                       std::string& reason);
  void check_committed(const NodeSpec& spec, const Trajectory& committed,
                       std::vector<Job>& jobs) const;
  const JobSet* set_of(const std::string& job_id) const;
  void keep_as_set(JobSet set, const std::vector<Job>& jobs);
  const Job* working_job(const std::string& id) const;
  bool place_dependent(const std::vector<JobSpec>& jobs,
                       const std::map<std::string, std::vector<std::string>>& depends,
                       std::map<std::string, double> placed, const std::optional<Point>& at,
                       TransactionId tx, ScheduleResult& result);
  // Where robots stand after their last job, if inside `area`: places a job there may be done
  // that the samples of Anhang A.1 need not offer. In a crowded area robots parked at earlier
  // jobs block the samples, and the robot standing in the area could do the job where it stands.
  // (Whether a node may stand there is checked as for any location, in qualifying_slots.)
  std::vector<Point> parked_in(const Polygon& area) const;
  bool try_schedule(const JobSpec& spec, TransactionId tx, const std::optional<Point>& at,
                    std::string& reason, Job& scheduled);
  bool try_candidate(const Slot& c, const JobSpec& spec, TransactionId tx, Job& scheduled);
  ScheduleResult removal(const std::string& job_id, bool replan);
  bool try_unschedule(const std::string& job_id, TransactionId tx, bool replan,
                      std::string& reason);
  std::optional<Trajectory> idle_tail(const NodeState& n, const TrajectoryPlanner& planner,
                                      const Point& at, double t) const;
  bool locked_by_other(const NodeState& n, TransactionId tx, double lo, double hi) const;
  void record(TransactionId tx, NodeState& n, double lo, double hi);
  const SpatialPathFinder& finder(const NodeState& n) const;
  std::vector<MovingObstacle> obstacles_for(const NodeState& n) const;
  TrajectoryPlanner::PathFunction path_function(const NodeState& n) const;
  void validate(const JobSpec& spec, bool allow_existing) const;
  bool job_exists(const std::string& id) const;
  void finish(TransactionId tx, const std::string& node, bool commit);

  World world_;
  SchedulerSettings settings_;
  std::vector<std::unique_ptr<NodeState>> nodes_;
  mutable std::map<double, std::unique_ptr<SpatialPathFinder>> finders_;  // by node radius
  mutable std::map<std::pair<double, double>, std::unique_ptr<DubinsPathFinder>> dubins_finders_;
  std::map<TransactionId, Transaction> transactions_;
  std::map<std::string, std::shared_ptr<const JobSet>> sets_;  // by member job id
  std::map<std::string, Job> lost_;  // set members of broken-down nodes, as they were, by id
  std::set<std::string> excluded_;
  TransactionId next_transaction_ = 1;
};

}  // namespace oscar::swarm
