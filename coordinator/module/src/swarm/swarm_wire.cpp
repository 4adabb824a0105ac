#include "swarm_wire.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <oscar/swarm_yaml.hpp>

namespace oscar::coordinator::swarm_wire {

std::int64_t Clock::ns(double seconds) const {
  return epoch_ns + static_cast<std::int64_t>(std::llround(seconds * 1e9));
}

std::string kind_name(SwarmRequestKind kind) {
  switch (kind) {
    case SWARM_SCHEDULE:
      return "schedule";
    case SWARM_PERIODIC:
      return "periodic";
    case SWARM_DEPENDENT:
      return "dependent";
    case SWARM_UNSCHEDULE:
      return "unschedule";
    case SWARM_RESCHEDULE:
      return "reschedule";
    case SWARM_UNSCHEDULE_SET:
      return "unschedule_set";
    case SWARM_ADD_OBSTACLES:
      return "add_obstacles";
    case SWARM_REMOVE_OBSTACLES:
      return "remove_obstacles";
  }
  return "request kind " + std::to_string(static_cast<int>(kind));
}

swarm::JobSpec job_spec(const SwarmJobSpec& wire, const Clock& clock) {
  const std::string what = fmt::format("job '{}'", wire.id());
  const auto& xs = wire.area().x();
  const auto& ys = wire.area().y();
  if (xs.size() != ys.size()) {
    throw std::invalid_argument(
        fmt::format("{} area: {} x but {} y coordinates", what, xs.size(), ys.size()));
  }
  std::vector<swarm::Point> points;
  for (std::size_t i = 0; i < xs.size(); ++i) points.emplace_back(xs[i], ys[i]);
  swarm::JobSpec spec;
  spec.id = wire.id();
  spec.area = swarm::make_polygon(points, what + " area");
  spec.earliest_start = clock.seconds(wire.earliest_start_ns());
  spec.latest_finish = clock.seconds(wire.latest_finish_ns());
  spec.duration = wire.duration_s();
  return spec;
}

namespace {

SwarmArea area(const swarm::Polygon& polygon) {
  SwarmArea a;
  for (const auto& p : swarm::vertices(polygon)) {
    a.x().push_back(p.x());
    a.y().push_back(p.y());
  }
  return a;
}

}  // namespace

SwarmJobSpec wire_job_spec(const swarm::JobSpec& spec, const Clock& clock) {
  SwarmJobSpec wire;
  wire.id(spec.id);
  wire.area(area(spec.area));
  wire.earliest_start_ns(clock.ns(spec.earliest_start));
  wire.latest_finish_ns(clock.ns(spec.latest_finish));
  wire.duration_s(spec.duration);
  return wire;
}

bool CommittedPlan::idle() const {
  if (!jobs.empty()) return false;
  const auto& points = trajectory.points();
  return std::all_of(points.begin(), points.end(), [&](const swarm::Waypoint& w) {
    return w.x == points.front().x && w.y == points.front().y;
  });
}

CommittedPlan committed_plan(const std::string& robot, const std::string& answer,
                             const Clock& clock) {
  const Trajectory t = trajectory_from_yaml(answer);
  if (t.robot() != robot) {
    throw std::invalid_argument(
        fmt::format("the committed plan names robot '{}', not '{}'", t.robot(), robot));
  }
  if (t.sections().size() != 1 || !t.sections()[0].open_end() ||
      t.sections()[0].waypoints().empty()) {
    throw std::invalid_argument(
        "a committed plan is one open-ended section with waypoints, from the robot's now on");
  }
  CommittedPlan plan;
  std::vector<swarm::Waypoint> points;
  for (const auto& w : t.sections()[0].waypoints()) {
    points.push_back({w.x(), w.y(), clock.seconds(w.t_ns())});
  }
  plan.trajectory = swarm::Trajectory(std::move(points));
  for (const auto& j : t.jobs_added()) {
    if (j.end_ns() < j.start_ns()) {
      throw std::invalid_argument(fmt::format("job '{}' ends at {} ns, before it starts at {} ns",
                                              j.id(), j.end_ns(), j.start_ns()));
    }
    const double start = clock.seconds(j.start_ns());
    const double duration = clock.seconds(j.end_ns()) - start;
    const double h = kTakenOverJobArea / 2;
    swarm::JobSpec spec{j.id(),
                        swarm::make_polygon({{j.x() - h, j.y() - h},
                                             {j.x() + h, j.y() - h},
                                             {j.x() + h, j.y() + h},
                                             {j.x() - h, j.y() + h}},
                                            fmt::format("job '{}' area", j.id())),
                        clock.seconds(j.earliest_start_ns()), clock.seconds(j.latest_finish_ns()),
                        duration};
    plan.jobs.push_back({j.id(), robot, j.x(), j.y(), start, duration, std::move(spec)});
  }
  std::sort(plan.jobs.begin(), plan.jobs.end(),
            [](const swarm::Job& a, const swarm::Job& b) { return a.start < b.start; });
  return plan;
}

namespace {

const SwarmJobSpec& first_job(const SwarmRequest& r) {
  if (r.jobs().empty()) {
    throw std::invalid_argument(
        fmt::format("a {} request needs its job in `jobs`", kind_name(r.kind())));
  }
  return r.jobs().front();
}

const std::string& job_id(const SwarmRequest& r) {
  if (r.job_id().empty()) {
    throw std::invalid_argument(
        fmt::format("a {} request names its job in `job_id`", kind_name(r.kind())));
  }
  return r.job_id();
}

}  // namespace

swarm::ScheduleResult apply(swarm::Scheduler& scheduler, const SwarmRequest& r,
                            const Clock& clock) {
  switch (r.kind()) {
    case SWARM_SCHEDULE:
      return scheduler.schedule(job_spec(first_job(r), clock));
    case SWARM_RESCHEDULE:
      return scheduler.reschedule(job_spec(first_job(r), clock));
    case SWARM_UNSCHEDULE:
      return scheduler.unschedule(job_id(r));
    case SWARM_UNSCHEDULE_SET:
      return scheduler.unschedule_set(job_id(r));
    case SWARM_PERIODIC: {
      const auto j = job_spec(first_job(r), clock);
      return scheduler.schedule(swarm::PeriodicSpec{r.periodic_ids(), j.area, r.same_location(),
                                                    j.earliest_start, r.period_s(), j.duration});
    }
    case SWARM_DEPENDENT: {
      swarm::DependentSpec d;
      for (const auto& j : r.jobs()) d.jobs.push_back(job_spec(j, clock));
      for (const auto& dep : r.depends()) d.depends[dep.job()] = dep.after();
      return scheduler.schedule(d);
    }
    case SWARM_ADD_OBSTACLES:
    case SWARM_REMOVE_OBSTACLES:
      break;  // the world's, not the planner's jobs': the service changes the world
  }
  throw std::invalid_argument(kind_name(r.kind()) + " is no job request");
}

SwarmPlacedJob placed(const swarm::Job& job, const Clock& clock) {
  SwarmPlacedJob p;
  p.id(job.id);
  p.robot(job.node);
  p.x(job.x);
  p.y(job.y);
  p.start_ns(clock.ns(job.start));
  p.duration_s(job.duration);
  p.earliest_start_ns(clock.ns(job.spec.earliest_start));
  p.latest_finish_ns(clock.ns(job.spec.latest_finish));
  return p;
}

Trajectory proposal(const swarm::Scheduler& scheduler, swarm::TransactionId tx,
                    const swarm::Scheduler::NodeChange& change, const Clock& clock) {
  Trajectory t;
  t.robot(change.node);
  t.transaction(tx);
  const auto& working = scheduler.trajectory(change.node, false);
  for (const auto& [lo, hi] : change.sections) {
    const auto part = swarm::Trajectory().spliced(working, lo, hi);
    TrajectorySection s;
    s.from_ns(clock.ns(lo));
    s.open_end(hi >= swarm::kForever);
    s.to_ns(clock.ns(s.open_end() ? part.end_time() : hi));
    for (const auto& w : part.points()) {
      SwarmWaypoint p;
      p.x(w.x);
      p.y(w.y);
      p.t_ns(clock.ns(w.t));
      s.waypoints().push_back(p);
    }
    t.sections().push_back(std::move(s));
  }
  for (const auto& j : change.added) {
    RobotJob job;
    job.id(j.id);
    job.x(j.x);
    job.y(j.y);
    job.start_ns(clock.ns(j.start));
    job.end_ns(clock.ns(j.end()));
    job.earliest_start_ns(clock.ns(j.spec.earliest_start));
    job.latest_finish_ns(clock.ns(j.spec.latest_finish));
    t.jobs_added().push_back(job);
  }
  t.jobs_removed(change.removed);
  return t;
}

namespace {

// The waypoints of `trajectory`, up to the last one before kForever.
std::vector<SwarmWaypoint> waypoints(const swarm::Trajectory& trajectory, const Clock& clock) {
  std::vector<SwarmWaypoint> out;
  for (const auto& w : trajectory.points()) {
    if (w.t >= swarm::kForever) break;
    SwarmWaypoint p;
    p.x(w.x);
    p.y(w.y);
    p.t_ns(clock.ns(w.t));
    out.push_back(p);
  }
  return out;
}

}  // namespace

SwarmPlan plan(const swarm::Scheduler& scheduler, const Clock& clock) {
  SwarmPlan plan;
  plan.now_ns(clock.ns(scheduler.present()));
  for (const auto& o : scheduler.world().static_obstacles)
    plan.static_obstacles().push_back(area(o));
  for (const auto& o : scheduler.world().dynamic_obstacles) {
    SwarmMovingObstacle m;
    m.shape(area(o.shape));
    m.path(waypoints(o.trajectory, clock));
    plan.moving_obstacles().push_back(std::move(m));
  }
  for (const auto& id : scheduler.node_ids()) {
    SwarmPath path;
    path.robot(id);
    path.radius(scheduler.node(id).radius_m);
    path.waypoints(waypoints(scheduler.trajectory(id), clock));
    plan.paths().push_back(std::move(path));
  }
  plan.jobs(upcoming_jobs(scheduler, clock));
  return plan;
}

std::vector<SwarmPlacedJob> upcoming_jobs(const swarm::Scheduler& scheduler, const Clock& clock) {
  std::vector<SwarmPlacedJob> out;
  for (const auto& id : scheduler.node_ids()) {
    for (const auto& j : scheduler.jobs(id)) {
      if (j.end() > scheduler.present()) out.push_back(placed(j, clock));
    }
  }
  return out;
}

}  // namespace oscar::coordinator::swarm_wire
