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
      keep_as_set(what, result.jobs);
      return result;
    }
    abort(tx);  // all or nothing (§4.2.2)
  }
  return result;
}

ScheduleResult Scheduler::schedule(const DependentSpec& spec) {
  if (spec.jobs.empty()) throw std::invalid_argument("dependent jobs: jobs must not be empty");
  for (const auto& j : spec.jobs) validate(j, false);
  auto windows = implicit_windows(spec.jobs, spec.depends, settings_.dependency_margin);
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
  std::map<std::string, double> fixed;
  std::set<std::string> pending;
  for (const auto& j : spec.jobs) pending.insert(j.id);
  while (!pending.empty()) {
    // A.3: among jobs whose dependencies are scheduled, the earliest implicit deadline first.
    const JobSpec* next = nullptr;
    for (const auto& j : spec.jobs) {
      if (!pending.count(j.id)) continue;
      bool ready = true;
      if (auto it = spec.depends.find(j.id); it != spec.depends.end()) {
        for (const auto& a : it->second) ready = ready && fixed.count(a);
      }
      if (ready && (!next || windows.at(j.id).latest_start < windows.at(next->id).latest_start)) {
        next = &j;
      }
    }
    JobSpec implicit = *next;
    implicit.earliest_start = windows.at(next->id).earliest_start;
    implicit.latest_finish = windows.at(next->id).latest_start + next->duration;
    Job scheduled;
    if (implicit.earliest_start > windows.at(next->id).latest_start ||
        !try_schedule(implicit, tx, std::nullopt, result.reason, scheduled)) {
      if (result.reason.empty()) {
        result.reason = fmt::format("job '{}': implicit window became empty", next->id);
      }
      abort(tx);  // all or nothing
      result.jobs.clear();
      return result;
    }
    scheduled.spec = *next;
    result.jobs.push_back(scheduled);
    fixed[next->id] = scheduled.start;
    pending.erase(next->id);
    windows = implicit_windows(spec.jobs, spec.depends, settings_.dependency_margin, fixed);
  }
  result.ok = true;
  result.transaction = tx;
  keep_as_set(what, result.jobs);
  return result;
}

}  // namespace oscar::swarm
