// Atomic job sets: periodic (seed §4.2.3, A.2) and dependent (§4.2.4, A.3).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "oscar/swarm/dependency_windows.hpp"
#include "oscar/swarm/scheduler.hpp"
#include "scheduler_state.hpp"

namespace oscar::swarm {

ScheduleResult Scheduler::schedule(const PeriodicSpec& spec) {
  if (spec.ids.empty()) throw std::invalid_argument("periodic jobs: ids must not be empty");
  check_time(spec.start, "periodic jobs: start");
  if (!std::isfinite(spec.period) || !std::isfinite(spec.duration) || spec.duration <= 0 ||
      spec.period < spec.duration) {
    throw std::invalid_argument(
        "periodic jobs: need 0 < duration <= period (seed §4.2.3, d_P >= d)");
  }
  std::vector<JobSpec> jobs;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < spec.ids.size(); ++i) {
    if (!seen.insert(spec.ids[i]).second) {
      throw std::invalid_argument(fmt::format("periodic jobs: duplicate id '{}'", spec.ids[i]));
    }
    const double t_i = spec.start + static_cast<double>(i) * spec.period;
    jobs.push_back({spec.ids[i], spec.area, t_i, t_i + spec.period, spec.duration});
    validate(jobs.back(), false);
  }
  ScheduleResult result;
  // Same location: one location for all repetitions, tried in turn (A.2); independent: each job
  // samples its own.
  const auto locations = spec.same_location ? sample_locations(spec.area, world_.static_obstacles,
                                                               settings_.location_samples)
                                            : std::vector<Point>{Point()};
  const std::string what = "periodic set " + fmt::format("{}", fmt::join(spec.ids, ", "));
  for (const auto& p : locations) {
    const TransactionId tx = open_transaction(true, what);
    std::vector<Job> done;
    bool ok = true;
    for (const auto& job : jobs) {
      Job scheduled;
      const std::optional<Point> at = spec.same_location ? std::optional<Point>(p) : std::nullopt;
      if (!try_schedule(job, tx, at, result.reason, scheduled)) {
        ok = false;
        break;
      }
      done.push_back(scheduled);
    }
    if (ok) {
      result.ok = true;
      result.reason.clear();
      result.transaction = tx;
      result.jobs = std::move(done);
      keep_as_set({.what = what, .same_location = spec.same_location}, result.jobs);
      return result;
    }
    abort(tx);  // all or nothing (§4.2.2)
  }
  return result;
}

ScheduleResult Scheduler::schedule(const DependentSpec& spec) {
  if (spec.jobs.empty()) throw std::invalid_argument("dependent jobs: jobs must not be empty");
  for (const auto& j : spec.jobs) validate(j, false);
  const auto windows = implicit_windows(spec.jobs, spec.depends, settings_.dependency_margin);
  ScheduleResult result;
  for (const auto& j : spec.jobs) {
    const auto& w = windows.at(j.id);
    if (w.earliest_start > w.latest_start) {
      result.reason = fmt::format("job '{}': implicit window [{}, {}] is empty (eq. 4.10/4.11)",
                                  j.id, w.earliest_start, w.latest_start);
      return result;
    }
  }
  std::vector<std::string> ids;
  for (const auto& j : spec.jobs) ids.push_back(j.id);
  const std::string what = "dependent set " + fmt::format("{}", fmt::join(ids, ", "));
  const TransactionId tx = open_transaction(true, what);
  if (!place_dependent(spec.jobs, spec.depends, {}, std::nullopt, tx, result)) {
    abort(tx);  // all or nothing
    return result;
  }
  result.ok = true;
  result.transaction = tx;
  keep_as_set({.what = what, .depends = spec.depends}, result.jobs);
  return result;
}

bool Scheduler::place_dependent(const std::vector<JobSpec>& jobs,
                                const std::map<std::string, std::vector<std::string>>& depends,
                                std::map<std::string, double> placed,
                                const std::optional<Point>& at, TransactionId tx,
                                ScheduleResult& result) {
  auto windows = implicit_windows(jobs, depends, settings_.dependency_margin, placed);
  std::set<std::string> pending;
  for (const auto& j : jobs) {
    if (!placed.contains(j.id)) pending.insert(j.id);
  }
  while (!pending.empty()) {
    // A.3: among jobs whose dependencies are scheduled, the earliest implicit deadline first.
    const JobSpec* next = nullptr;
    for (const auto& j : jobs) {
      if (!pending.count(j.id)) continue;
      bool ready = true;
      if (auto it = depends.find(j.id); it != depends.end()) {
        for (const auto& a : it->second) ready = ready && placed.count(a);
      }
      if (ready && (!next || windows.at(j.id).latest_start < windows.at(next->id).latest_start)) {
        next = &j;
      }
    }
    const auto& w = windows.at(next->id);
    JobSpec implicit = *next;
    implicit.earliest_start = w.earliest_start;
    implicit.latest_finish = w.latest_start + next->duration;
    Job scheduled;
    if (w.earliest_start > w.latest_start) {
      result.reason = fmt::format("job '{}': implicit window [{}, {}] is empty (eq. 4.10/4.11)",
                                  next->id, w.earliest_start, w.latest_start);
      result.jobs.clear();
      return false;
    }
    if (!try_schedule(implicit, tx, at, result.reason, scheduled)) {
      result.jobs.clear();
      return false;
    }
    scheduled.spec = *next;
    result.jobs.push_back(scheduled);
    placed[next->id] = scheduled.start;
    pending.erase(next->id);
    windows = implicit_windows(jobs, depends, settings_.dependency_margin, placed);
  }
  return true;
}

ScheduleResult Scheduler::schedule_lost(const std::string& member_id) {
  const JobSet* set = set_of(member_id);
  if (!set) {
    throw std::invalid_argument(
        fmt::format("job '{}' belongs to no periodic or dependent set", member_id));
  }
  // The set as it stands: members placed (their starts are fixed), members lost and not being
  // placed by an open transaction, and members done so long ago that they are forgotten.
  std::vector<JobSpec> jobs;
  std::map<std::string, double> placed;
  std::optional<Point> at;
  for (const auto& id : set->ids) {
    if (const Job* j = working_job(id)) {
      jobs.push_back(j->spec);
      placed[id] = j->start;
    } else if (const auto lost = lost_.find(id); lost != lost_.end()) {
      jobs.push_back(lost->second.spec);
      if (set->same_location) at = lost->second.location();
    }
  }
  if (jobs.size() == placed.size()) {
    throw std::invalid_argument(fmt::format("the {} has no lost member to place again", set->what));
  }
  std::map<std::string, std::vector<std::string>> depends;  // among the members still known
  auto known = [&](const std::string& id) {
    return std::any_of(jobs.begin(), jobs.end(), [&](const JobSpec& j) { return j.id == id; });
  };
  for (const auto& [job, waits_for] : set->depends) {
    if (!known(job)) continue;
    for (const auto& a : waits_for) {
      if (known(a)) depends[job].push_back(a);
    }
  }
  ScheduleResult result;
  const TransactionId tx = open_transaction(true, "placing again of the " + set->what);
  if (!place_dependent(jobs, depends, std::move(placed), at, tx, result)) {
    abort(tx);  // all or nothing; the members stay lost
    return result;
  }
  result.ok = true;
  result.transaction = tx;
  return result;
}

}  // namespace oscar::swarm
