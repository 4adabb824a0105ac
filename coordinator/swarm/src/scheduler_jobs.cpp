// Single jobs: schedule (seed §4.2.1, A.4), unschedule and remove (§4.2.5), reschedule (§4.2.6).
#include <fmt/format.h>
#include <algorithm>
#include <cmath>

#include "boost_geometry.hpp"
#include "oscar/swarm/scheduler.hpp"
#include "oscar/swarm/trajectory_planner.hpp"
#include "scheduler_state.hpp"

namespace oscar::swarm {

namespace {

// Earliest s >= from with [s, s + d] clear of all blocked intervals, or nullopt beyond `latest`.
std::optional<double> next_free_start(const std::vector<std::pair<double, double>>& blocked,
                                      double from, double d, double latest) {
  double s = from;
  bool moved = true;
  while (moved) {
    moved = false;
    for (const auto& [lo, hi] : blocked) {
      if (lo < s + d && s < hi && std::min(hi, s + d) - std::max(lo, s) > kEpsilon) {
        s = hi;
        moved = true;
      }
    }
    if (s > latest) return std::nullopt;
  }
  return s;
}

}  // namespace

std::optional<Trajectory> Scheduler::idle_tail(const NodeState& n, const TrajectoryPlanner& planner,
                                               const Point& at, double t) const {
  // After its last job a node idles where it is, but it is not nailed there: if a moving obstacle
  // (or another node) comes by later, the node gets out of the way to a place that stays free for
  // good (choice documented in README.md, "Idle nodes"). Candidates: the place itself, then rings
  // of 8 points at 1, 2, 4, 8 and 16 m, then the node's start; nearest first.
  const auto blocked_here = planner.blocked_times(at, t, kForever);
  if (blocked_here.empty()) return Trajectory({{at.x(), at.y(), t}});
  std::vector<Point> spots;
  for (double r : {1.0, 2.0, 4.0, 8.0, 16.0}) {
    for (int k = 0; k < 8; ++k) {
      const double a = M_PI / 4 * k;
      spots.emplace_back(at.x() + r * std::cos(a), at.y() + r * std::sin(a));
    }
  }
  spots.emplace_back(n.spec.x, n.spec.y);
  std::stable_sort(spots.begin(), spots.end(), [&](const Point& a, const Point& b) {
    return distance(at, a) < distance(at, b);
  });
  const SpatialPathFinder& free_space = finder(n);
  // The nearest spot nothing crosses once the node is there; failing that, the nearest it can
  // reach once whatever crosses it has passed (an obstacle going round a loop, unrolled for a
  // span ahead, crosses its spots until the span ends: only the last resort).
  std::optional<Trajectory> after_passing;
  for (const auto& p : spots) {
    if (!free_space.is_free(p)) continue;
    const auto path = planner.path(at, p);
    if (!path) continue;
    const auto arrival = planner.earliest_arrival(*path, t, kForever / 2);
    if (!arrival) continue;
    double settle = *arrival;
    for (const auto& [lo, hi] : planner.blocked_times(p, t, kForever)) {
      if (hi > settle && hi - lo > kEpsilon) settle = std::max(settle, hi);
    }
    if (settle >= kForever / 2 || (after_passing && settle > *arrival)) continue;
    auto leg = planner.fixed_arrival(*path, t, settle);
    if (!leg || !planner.blocked_times(p, settle, kForever).empty()) continue;
    if (settle == *arrival) return leg;
    after_passing = std::move(leg);
  }
  return after_passing;
}

bool Scheduler::try_candidate(const Slot& c, const JobSpec& spec, TransactionId tx,
                              Job& scheduled) {
  NodeState& n = state(c.node);
  const double v = n.spec.max_speed_mps;
  const double t_min = std::max(spec.earliest_start, frozen_horizon_time());
  const double t_max = spec.latest_finish - spec.duration;  // latest start
  const bool has_next = c.index < n.working_jobs.size();
  TrajectoryPlanner planner(path_function(n), obstacles_for(n), {v, 0, settings_.wait_threshold});
  const auto path1 = planner.path(c.from, c.at);
  if (!path1) return false;
  const auto arrival = planner.earliest_arrival(*path1, c.t1, t_max);
  if (!arrival) return false;
  const double stay_until = has_next ? c.t2 : kForever;
  const auto blocked = planner.blocked_times(c.at, *arrival, stay_until);
  std::optional<std::vector<Point>> path2;
  if (has_next) {
    path2 = planner.path(c.at, n.working_jobs[c.index].location());
    if (!path2) return false;
  }
  double from = std::max(*arrival, t_min);
  for (int attempt = 0; attempt < 4; ++attempt) {
    const auto start = next_free_start(blocked, from, spec.duration, t_max);
    if (!start) return false;
    from = *start + std::max(spec.duration * 0.25, 1e-3);  // the next attempt starts later
    auto leg1 = planner.fixed_arrival(*path1, c.t1, *start);
    if (!leg1) continue;
    const double end = *start + spec.duration;
    Trajectory section = *leg1;
    section.append({c.at.x(), c.at.y(), end});
    if (has_next) {
      if (end + path_length(*path2) / v > c.t2 + 1e-9) return false;
      auto leg2 = planner.fixed_arrival(*path2, end, c.t2);
      if (!leg2) continue;
      section.append(*leg2);
    } else {
      auto tail = idle_tail(n, planner, c.at, end);
      if (!tail) continue;
      section.append(*tail);
    }
    record(tx, n, c.t1, stay_until);
    n.working = n.working.spliced(section, c.t1, stay_until);
    scheduled = Job{spec.id, n.spec.id, c.at.x(), c.at.y(), *start, spec.duration, spec};
    n.working_jobs.insert(n.working_jobs.begin() + static_cast<long>(c.index), scheduled);
    transactions_.at(tx).changes[n.spec.id].added.push_back(spec.id);
    return true;
  }
  return false;
}

bool Scheduler::try_schedule(const JobSpec& spec, TransactionId tx, const std::optional<Point>& at,
                             std::string& reason, Job& scheduled) {
  const double t_fh = frozen_horizon_time();
  const double t_min = std::max(spec.earliest_start, t_fh);  // t'_min of §4.2.1
  const double t_max = spec.latest_finish - spec.duration;
  if (t_min > t_max) {
    reason = fmt::format("job '{}': its latest start {} is before the frozen horizon {}", spec.id,
                         t_max, t_fh);
    return false;
  }
  auto locations =
      at ? std::vector<Point>{*at}
         : sample_locations(spec.area, world_.static_obstacles, settings_.location_samples);
  if (!at) {
    const auto parked = parked_in(spec.area);
    locations.insert(locations.end(), parked.begin(), parked.end());
  }
  bool any_location = false;
  bool any_slot = false;
  for (const auto& p : locations) {
    const auto candidates = qualifying_slots(spec, p, tx);
    for (const auto& node : nodes_) any_location = any_location || finder(*node).is_free(p);
    any_slot = any_slot || !candidates.empty();
    for (const auto& c : candidates) {
      if (try_candidate(c, spec, tx, scheduled)) return true;
    }
  }
  const bool any_node = std::any_of(nodes_.begin(), nodes_.end(), [&](const auto& n) {
    return !n->broken && !excluded_.contains(n->spec.id);
  });
  if (!any_node) {
    reason = fmt::format("job '{}': no node is in planning{}", spec.id,
                         excluded_.empty() ? "" : " (besides those that refused it)");
  } else if (locations.empty()) {
    reason = fmt::format("job '{}': its area lies wholly within static obstacles", spec.id);
  } else if (!any_location) {
    reason = fmt::format("job '{}': no sampled location in the area is free for any node", spec.id);
  } else if (!any_slot) {
    reason = fmt::format("job '{}': no node has an idle slot meeting conditions 4.2-4.4", spec.id);
  } else {
    reason =
        fmt::format("job '{}': no collision-free trajectory for any location and slot", spec.id);
  }
  return false;
}

std::vector<Point> Scheduler::parked_in(const Polygon& area) const {
  std::vector<Point> places;
  for (const auto& node : nodes_) {
    if (node->broken || node->working.points().empty()) continue;
    const auto& last = node->working.points().back();
    const Point p(last.x, last.y);
    if (boost::geometry::covered_by(p, area)) places.push_back(p);
  }
  return places;
}

std::vector<Slot> Scheduler::qualifying_slots(const JobSpec& spec, const Point& p,
                                              TransactionId tx) const {
  const double t_fh = frozen_horizon_time();
  const double t_min = std::max(spec.earliest_start, t_fh);  // t'_min of §4.2.1
  const double t_max = spec.latest_finish - spec.duration;
  std::vector<Slot> candidates;
  for (const auto& node : nodes_) {
    const NodeState& n = *node;
    if (n.broken || excluded_.contains(n.spec.id) || !finder(n).is_free(p)) continue;
    const double v = n.spec.max_speed_mps;
    for (std::size_t k = 0; k <= n.working_jobs.size(); ++k) {
      const double t1 = k == 0 ? n.spec.t : n.working_jobs[k - 1].end();
      const double t2 = k < n.working_jobs.size() ? n.working_jobs[k].start : kForever;
      if (t2 <= t_fh) continue;
      const double t1p = std::max(t1, t_fh);
      const Point from = n.working.position_at(t1p);
      const double s1 = distance(from, p);
      const double s2 = k < n.working_jobs.size() ? distance(p, n.working_jobs[k].location()) : 0;
      if (t_max - t1p < s1 / v) continue;                      // eq. 4.2
      if (t2 - t_min < s2 / v + spec.duration) continue;       // eq. 4.3
      if (t2 - t1p < (s1 + s2) / v + spec.duration) continue;  // eq. 4.4
      if (locked_by_other(n, tx, t1p, t2)) continue;           // §4.2.7
      const double s12 =
          k < n.working_jobs.size() ? distance(from, n.working_jobs[k].location()) : 0;
      candidates.push_back({n.spec.id, k, t1p, t2, from, p, s1 + s2 - s12});  // eq. 4.5
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Slot& a, const Slot& b) { return a.detour < b.detour; });
  return candidates;
}

ScheduleResult Scheduler::schedule(const JobSpec& spec) {
  validate(spec, false);
  ScheduleResult result;
  const TransactionId tx = open_transaction();
  Job job;
  if (!try_schedule(spec, tx, std::nullopt, result.reason, job)) {
    abort(tx);
    return result;
  }
  result.ok = true;
  result.transaction = tx;
  result.jobs.push_back(job);
  return result;
}

bool Scheduler::try_unschedule(const std::string& job_id, TransactionId tx, bool replan,
                               std::string& reason) {
  for (auto& node : nodes_) {
    NodeState& n = *node;
    auto& list = n.working_jobs;
    const auto it =
        std::find_if(list.begin(), list.end(), [&](const Job& j) { return j.id == job_id; });
    if (it == list.end()) continue;
    const std::size_t k = static_cast<std::size_t>(it - list.begin());
    const double t_fh = frozen_horizon_time();
    if (it->start < t_fh) {
      reason = fmt::format("job '{}' starts at {}, before the frozen horizon {}", job_id, it->start,
                           t_fh);
      return false;
    }
    const double t1 = std::max(k == 0 ? n.spec.t : list[k - 1].end(), t_fh);
    const double t2 = k + 1 < list.size() ? list[k + 1].start : kForever;
    const double lo = replan ? t1 : it->start;
    const double hi = replan ? t2 : it->end();
    if (locked_by_other(n, tx, lo, hi)) {
      reason =
          fmt::format("job '{}': its trajectory section is locked by another transaction", job_id);
      return false;
    }
    if (replan) {
      TrajectoryPlanner planner(path_function(n), obstacles_for(n),
                                {n.spec.max_speed_mps, 0, settings_.wait_threshold});
      const Point from = n.working.position_at(t1);
      std::optional<Trajectory> section;
      if (k + 1 < list.size()) {
        const auto path = planner.path(from, list[k + 1].location());
        if (path) section = planner.fixed_arrival(*path, t1, t2);
      } else {
        section = idle_tail(n, planner, from, t1);
      }
      if (!section) {
        reason = fmt::format("job '{}': no collision-free trajectory around the gap", job_id);
        return false;
      }
      n.working = n.working.spliced(*section, t1, t2);
    }
    record(tx, n, lo, hi);
    transactions_.at(tx).changes[n.spec.id].removed.push_back(*it);
    list.erase(it);
    return true;
  }
  for (const auto& node : nodes_) {
    for (const auto& j : node->committed_jobs) {
      if (j.id == job_id) {  // §4.2.7: a job being removed is locked against another removal
        reason = fmt::format("job '{}' is locked: an open transaction removes it", job_id);
        return false;
      }
    }
  }
  throw std::invalid_argument(fmt::format("unknown job id '{}'", job_id));
}

namespace {

std::string set_member_refusal(const std::string& job_id, const std::string& set) {
  return fmt::format(
      "job '{}' belongs to the {}: alone it cannot be unscheduled, removed or rescheduled without "
      "breaking the set's guarantee (seed §4.2.2-4.2.4); unschedule the set as a whole",
      job_id, set);
}

}  // namespace

// unschedule and remove_job: one removal in a transaction of its own, kept on success, aborted
// on failure or throw.
ScheduleResult Scheduler::removal(const std::string& job_id, bool replan) {
  ScheduleResult result;
  if (const JobSet* set = set_of(job_id)) {
    result.reason = set_member_refusal(job_id, set->what);
    return result;
  }
  const TransactionId tx = open_transaction();
  try {
    result.ok = try_unschedule(job_id, tx, replan, result.reason);
  } catch (...) {
    abort(tx);
    throw;
  }
  if (!result.ok) {
    abort(tx);
  } else {
    result.transaction = tx;
  }
  return result;
}

ScheduleResult Scheduler::unschedule(const std::string& job_id) { return removal(job_id, true); }

ScheduleResult Scheduler::remove_job(const std::string& job_id) { return removal(job_id, false); }

ScheduleResult Scheduler::unschedule_set(const std::string& member_id) {
  const JobSet* set = set_of(member_id);
  if (!set) {
    if (!job_exists(member_id)) {
      throw std::invalid_argument(fmt::format("unknown job id '{}'", member_id));
    }
    throw std::invalid_argument(
        fmt::format("job '{}' belongs to no periodic or dependent set", member_id));
  }
  const auto keep = sets_.at(member_id);  // the set outlives its members' removal below
  ScheduleResult result;
  const TransactionId tx = open_transaction(true, "unscheduling of the " + keep->what);
  const double t_fh = frozen_horizon_time();
  try {
    for (const auto& id : keep->ids) {
      const auto job = std::find_if(nodes_.begin(), nodes_.end(), [&](const auto& n) {
        return std::any_of(n->working_jobs.begin(), n->working_jobs.end(),
                           [&](const Job& j) { return j.id == id && j.start >= t_fh; });
      });
      if (job == nodes_.end()) {  // started already, gone with a removed node, or lost
        if (lost_.contains(id) && !job_exists(id)) {
          transactions_.at(tx).lost_given_up.push_back(id);
        }
        continue;
      }
      if (!try_unschedule(id, tx, true, result.reason)) {
        abort(tx);
        return result;
      }
    }
  } catch (...) {
    abort(tx);
    throw;
  }
  result.ok = true;
  result.transaction = tx;
  return result;
}

ScheduleResult Scheduler::reschedule(const JobSpec& spec) {
  validate(spec, true);
  ScheduleResult result;
  if (const JobSet* set = set_of(spec.id)) {
    result.reason = set_member_refusal(spec.id, set->what);
    return result;
  }
  const TransactionId tx = open_transaction(true, fmt::format("rescheduling of job '{}'", spec.id));
  Job job;
  try {
    if (try_unschedule(spec.id, tx, true, result.reason) &&
        try_schedule(spec, tx, std::nullopt, result.reason, job)) {
      result.ok = true;
      result.transaction = tx;
      result.jobs.push_back(job);
      return result;
    }
  } catch (...) {
    abort(tx);
    throw;
  }
  abort(tx);
  return result;
}

}  // namespace oscar::swarm
