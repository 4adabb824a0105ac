// The world changing while the swarm runs: Scheduler::change_world.
#include <fmt/format.h>
#include <algorithm>

#include "oscar/swarm/dubins_path_finder.hpp"
#include "oscar/swarm/scheduler.hpp"
#include "oscar/swarm/trajectory_planner.hpp"
#include "scheduler_state.hpp"

namespace oscar::swarm {

namespace {
std::string place_text(const Point& p) { return fmt::format("({:.2f}, {:.2f})", p.x(), p.y()); }
}  // namespace

WorldChange Scheduler::change_world(World world) {
  check_world(world);
  if (!transactions_.empty()) {
    throw std::invalid_argument(
        fmt::format("the world changes only while no transaction is open; transaction {} is",
                    transactions_.begin()->first));
  }
  World old = std::exchange(world_, std::move(world));
  auto finders = std::exchange(finders_, {});  // they hold the static obstacles, grown
  auto dubins_finders = std::exchange(dubins_finders_, {});
  WorldChange result;
  auto refuse = [&](TransactionId tx) {
    if (tx) abort(tx);
    world_ = std::move(old);
    finders_ = std::move(finders);
    dubins_finders_ = std::move(dubins_finders);
    result.ok = false;
    return result;
  };
  const TransactionId tx = open_transaction(true, "re-planning in the changed world");
  try {
    for (auto& node : nodes_) {
      NodeState& n = *node;
      if (n.broken) continue;  // it stands where it stopped, whatever the world
      if (const auto t = runs_into_world(n, settings_.present, frozen_horizon_time())) {
        result.reason = fmt::format(
            "node '{}' runs into the changed world at {} at t = {:.3f} ({:.3f} s from now), "
            "before the frozen horizon ({:.3f} s from now), where its trajectory cannot change "
            "any more",
            n.spec.id, place_text(n.committed.position_at(*t)), *t, *t - settings_.present,
            settings_.frozen_horizon);
        return refuse(tx);
      }
      if (!runs_into_world(n, frozen_horizon_time(), kForever)) continue;
      if (!replan_in_world(n, tx, result.displaced, result.reason)) return refuse(tx);
      result.nodes.push_back(n.spec.id);
    }
  } catch (...) {
    refuse(tx);
    throw;
  }
  for (const auto& j : result.displaced) {
    if (set_of(j.id)) transactions_.at(tx).displaced_members.push_back(j);
  }
  result.ok = true;
  if (result.nodes.empty()) {
    abort(tx);  // nothing changed: no transaction to commit
  } else {
    result.transaction = tx;
  }
  return result;
}

// The first time in [lo, hi] at which node n's committed trajectory runs into the world: a
// static obstacle grown by its radius, or a moving one.
std::optional<double> Scheduler::runs_into_world(const NodeState& n, double lo, double hi) const {
  const SpatialPathFinder& free_space = finder(n);
  Point a = n.committed.position_at(lo);
  if (!free_space.is_free(a)) return lo;
  double t = lo;
  for (const auto& w : n.committed.points()) {
    if (w.t <= lo) continue;
    if (w.t >= hi) break;
    const Point b(w.x, w.y);
    if (!free_space.visible(a, b)) return t;
    a = b;
    t = w.t;
  }
  if (!free_space.visible(a, n.committed.position_at(hi))) return t;
  std::vector<MovingObstacle> moving;
  for (const auto& o : world_.dynamic_obstacles) {
    moving.push_back({inflate(o.shape, n.spec.radius_m + 1e-6), o.trajectory});
  }
  if (moving.empty()) return std::nullopt;
  const TrajectoryPlanner world_only(path_function(n), std::move(moving),
                                     {n.spec.max_speed_mps, 0, 0});
  return world_only.first_hit(n.committed, lo, hi);
}

// Plans node n again from the frozen horizon in the (changed) world, in transaction tx: its jobs
// at their place and start where it still gets there, the others into `displaced`.
bool Scheduler::replan_in_world(NodeState& n, TransactionId tx, std::vector<Job>& displaced,
                                std::string& reason) {
  const double t_fh = frozen_horizon_time();
  const TrajectoryPlanner planner(path_function(n), obstacles_for(n),
                                  {n.spec.max_speed_mps, 0, settings_.wait_threshold});
  const SpatialPathFinder& free_space = finder(n);
  auto place_free = [&](const Point& p, double lo, double hi) {
    return free_space.is_free(p) && planner.blocked_times(p, lo, hi).empty();
  };
  Point at = n.committed.position_at(t_fh);
  double t = t_fh;
  Trajectory section({{at.x(), at.y(), t}});
  std::vector<Job> kept_jobs;
  for (const Job& j : n.committed_jobs) {
    if (j.end() <= t_fh) {
      kept_jobs.push_back(j);
      continue;
    }
    const Point p = j.location();
    if (j.start < t_fh) {  // worked across the frozen horizon: it stays where it is
      if (!place_free(p, t_fh, j.end())) {
        reason = fmt::format(
            "node '{}' works job '{}' at {} until {:.3f}, which the changed world covers after "
            "the frozen horizon {:.3f}",
            n.spec.id, j.id, place_text(p), j.end(), t_fh);
        return false;
      }
    } else {  // ahead: kept if the node still gets there by its start
      std::optional<Trajectory> leg;
      if (place_free(p, j.start, j.end())) {
        if (const auto path = planner.path(at, p)) leg = planner.fixed_arrival(*path, t, j.start);
      }
      if (!leg) {
        displaced.push_back(j);
        continue;
      }
      section.append(*leg);
    }
    section.append({p.x(), p.y(), j.end()});
    kept_jobs.push_back(j);
    at = p;
    t = j.end();
  }
  const auto tail = idle_tail(n, planner, at, t);
  if (!tail) {
    reason = fmt::format(
        "node '{}' finds no place to wait at or near {} after {:.3f} in the changed world",
        n.spec.id, place_text(at), t);
    return false;
  }
  section.append(*tail);
  record(tx, n, t_fh, kForever);
  n.working = n.working.spliced(section, t_fh, kForever);
  auto& change = transactions_.at(tx).changes[n.spec.id];
  for (const Job& j : n.working_jobs) {
    const bool kept =
        std::any_of(kept_jobs.begin(), kept_jobs.end(), [&](const Job& k) { return k.id == j.id; });
    if (!kept) change.removed.push_back(j);
  }
  n.working_jobs = std::move(kept_jobs);
  return true;
}

}  // namespace oscar::swarm
