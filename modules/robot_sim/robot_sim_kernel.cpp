#include "robot_sim_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <oscar/kernel_registry.hpp>
#include <oscar/swarm_yaml.hpp>

namespace oscar::modules {
namespace {
constexpr double kPlaceTolerance = 0.01;  // m: a section starts (ends) where the robot is
constexpr double kSpeedTolerance = 1e-4;  // relative: a leg may exceed max_speed by this much
constexpr double kStill = 1e-9;           // m: a leg shorter than this does not move the robot

std::vector<TimedPoint> points_of(const TrajectorySection& s) {
  std::vector<TimedPoint> points;
  points.reserve(s.waypoints().size());
  for (const auto& w : s.waypoints()) points.push_back({w.x(), w.y(), w.t_ns()});
  return points;
}

std::string place_text(const Place& p) { return fmt::format("({:.3f}, {:.3f})", p.x, p.y); }

double ms_between(Stamp earlier, Stamp later) { return static_cast<double>(later - earlier) / 1e6; }

// The sections' indices in the order they start.
std::vector<std::size_t> by_start(const Trajectory& t) {
  std::vector<std::size_t> order(t.sections().size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return t.sections()[a].from_ns() < t.sections()[b].from_ns();
  });
  return order;
}
}  // namespace

void RobotSim::Params::describe(ParamSpec& spec) {
  spec.field("radius", radius, "the robot is a disc of this radius, m").range(0.001, 1000).fixed();
  spec.field("max_speed", max_speed, "its top speed, m/s: a proposal with a faster leg is refused")
      .range(0.001, 1000)
      .fixed();
  spec.field("turning_radius", turning_radius,
             "its smallest turning radius, m, as published (0 = turns on the spot)")
      .range(0, 1000)
      .fixed();
  spec.field("start_x", start_x, "where it stands at first, m").range(-1e7, 1e7).fixed();
  spec.field("start_y", start_y, "where it stands at first, m").range(-1e7, 1e7).fixed();
  spec.field("start_heading", start_heading, "where it faces at first, rad ccw from +x")
      .range(-2 * M_PI, 2 * M_PI)
      .fixed();
  spec.field("nak_probability", nak_probability,
             "fault injection: the probability of refusing an otherwise acceptable proposal")
      .range(0, 1);
  spec.field("seed", seed, "fault injection: the seed of the random refusals").at_least(0).fixed();
  spec.field("breakdown_after_s", breakdown_after_s,
             "fault injection: it breaks down this many seconds after activation (negative: never)")
      .range(-1e9, 1e9);
  spec.field("ack_delay_ms", ack_delay_ms,
             "fault injection: the answer to a proposal waits this long, ms (keep it below the "
             "module's watchdog)")
      .range(0, 60000);
  spec.field("undecided_for", undecided_for,
             "a proposal with no commit or abort is dropped once its first section began this "
             "long ago (a coordinator that restarted forgot its open transactions)")
      .range(0.001, 3600);
}

RobotSim::RobotSim(KernelSetup& setup)
    : state_(setup.output<RobotState>("state")), name_(setup.kernel_name()), committed_(0, 0, 0) {
  setup.params(params_);
  setup.command<Trajectory>("propose", [this](const Trajectory& r) { return propose(r); });
  setup.command<TransactionDecision>("commit",
                                     [this](const TransactionDecision& d) { return commit(d); });
  setup.command<TransactionDecision>("abort",
                                     [this](const TransactionDecision& d) { return abort(d); });
  setup.command<CommittedPlanQuery>(
      "committed", [this](const CommittedPlanQuery& q) { return committed_plan(q); });
  committed_ = PilotTrajectory(params_.start_x, params_.start_y, params_.start_heading);
  random_.seed(static_cast<std::uint64_t>(params_.seed));
}

void RobotSim::on_activate() { activated_at_.reset(); }

// The kernel's time is its cycles' (the frame's clock; the harness's in a test). A command
// arrives between cycles: its time is the last cycle's plus the time that has passed since.
Stamp RobotSim::command_time() const {
  if (!last_cycle_) return wall_now();
  const auto since = std::chrono::steady_clock::now() - last_cycle_steady_;
  return *last_cycle_ + std::chrono::duration_cast<std::chrono::nanoseconds>(since).count();
}

void RobotSim::clock(Stamp now) {
  last_cycle_ = now;
  last_cycle_steady_ = std::chrono::steady_clock::now();
  if (!activated_at_) activated_at_ = now;
}

void RobotSim::break_down_if_due(Stamp now) {
  if (broken_ || !activated_at_ || params_.breakdown_after_s < 0) return;
  const Stamp due = *activated_at_ + std::llround(params_.breakdown_after_s * 1e9);
  if (now < due) return;
  committed_.stop_at(now);
  broken_ = true;
  fault_ = fmt::format("broke down {} s after activation (fault injection: breakdown_after_s)",
                       params_.breakdown_after_s);
}

RobotJob RobotSim::job_at(Stamp now) const {
  const RobotJob* working = nullptr;
  for (const auto& [id, job] : jobs_) {
    if (job.start_ns() <= now && now <= job.end_ns() &&
        (!working || job.start_ns() < working->start_ns())) {
      working = &job;
    }
  }
  return working ? *working : RobotJob{};
}

void RobotSim::process(Cycle& cycle) {
  const Stamp now = cycle.now();
  clock(now);
  break_down_if_due(now);
  if (broken_ && !fault_logged_) {
    cycle.log().warn("robot '{}' {}", name_, fault_);
    fault_logged_ = true;
  }
  committed_.forget_before(now);
  std::erase_if(jobs_, [&](const auto& kv) { return kv.second.end_ns() < now; });
  drop_undecided(cycle, now);
  RobotState s = state_at(now, committed_.at(now));
  if (!broken_) {
    s.job(job_at(now));
    s.transaction(committed_.transaction_at(now));
  }
  s.broken(broken_);
  s.fault(fault_);
  state_.publish(std::move(s));
}

// Stub: it stands at its start, whole, and works nothing.
void RobotSim::stub(Cycle& cycle) {
  clock(cycle.now());
  state_.publish(state_at(cycle.now(), Motion{params_.start_x, params_.start_y,
                                              std::remainder(params_.start_heading, 2 * M_PI), 0}));
}

// The state of this robot at `now` moving as `m`, working nothing.
RobotState RobotSim::state_at(Stamp now, const Motion& m) const {
  RobotState s;
  append_stamp(s.header(), now);
  s.robot(name_);
  s.radius(params_.radius);
  s.max_speed(params_.max_speed);
  s.turning_radius(params_.turning_radius);
  s.x(m.x);
  s.y(m.y);
  s.heading(m.heading);
  s.speed(m.speed);
  return s;
}

// Why the robot refuses a proposal arriving at `now`, or "" if it takes it.
std::string RobotSim::refusal(const Trajectory& request, Stamp now) const {
  if (request.robot() != name_) {
    return fmt::format("the proposal is for robot '{}', not '{}'", request.robot(), name_);
  }
  if (broken_) return fmt::format("robot '{}' is broken: {}", name_, fault_);
  if (request.transaction() == 0) return "transaction 0 names no transaction";
  const auto& sections = request.sections();
  for (std::size_t k = 0; k < sections.size(); ++k) {
    const auto& s = sections[k];
    const auto& w = s.waypoints();
    if (w.empty()) return fmt::format("section {} has no waypoints", k);
    if (!s.open_end() && s.to_ns() < s.from_ns()) {
      return fmt::format("section {} ends at {} ns, before it starts at {} ns", k, s.to_ns(),
                         s.from_ns());
    }
    for (std::size_t i = 0; i < w.size(); ++i) {
      if (!std::isfinite(w[i].x()) || !std::isfinite(w[i].y())) {
        return fmt::format("section {}: waypoint {} is no finite place", k, i);
      }
      if (i > 0 && w[i].t_ns() < w[i - 1].t_ns()) {
        return fmt::format(
            "section {}: the waypoints' times decrease: waypoint {} at {} ns, {} at {} ns", k,
            i - 1, w[i - 1].t_ns(), i, w[i].t_ns());
      }
      if (w[i].t_ns() < s.from_ns() || (!s.open_end() && w[i].t_ns() > s.to_ns())) {
        return fmt::format("section {}: waypoint {} at {} ns is outside the section [{}, {}]", k, i,
                           w[i].t_ns(), s.from_ns(),
                           s.open_end() ? std::string("open end") : fmt::format("{}", s.to_ns()));
      }
    }
  }
  const auto order = by_start(request);
  for (std::size_t n = 1; n < order.size(); ++n) {
    const auto& a = sections[order[n - 1]];
    const auto& b = sections[order[n]];
    if (a.open_end() || b.from_ns() < a.to_ns()) {
      return fmt::format("sections {} and {} overlap", order[n - 1], order[n]);
    }
  }
  for (std::size_t k = 0; k < sections.size(); ++k) {
    const auto& s = sections[k];
    if (s.from_ns() <= now) {
      return fmt::format(
          "the proposal arrives too late to take over: section {} starts at {} ns, {:.1f} ms "
          "before it arrived",
          k, s.from_ns(), ms_between(s.from_ns(), now));
    }
    const auto points = points_of(s);
    const auto is_at = [&](Stamp t) {
      const Motion m = committed_.at(t);
      return Place{m.x, m.y};
    };
    const auto far = [](const Place& a, const Place& b) {
      return std::hypot(a.x - b.x, a.y - b.y) > kPlaceTolerance;
    };
    if (const Place p = place_at(points, s.from_ns()), r = is_at(s.from_ns()); far(p, r)) {
      return fmt::format("section {} does not start where the robot will be at {} ns: {} vs {}", k,
                         s.from_ns(), place_text(p), place_text(r));
    }
    if (const Place p = place_at(points, s.to_ns()), r = is_at(s.to_ns());
        !s.open_end() && far(p, r)) {
      return fmt::format("section {} does not end where the robot will be at {} ns: {} vs {}", k,
                         s.to_ns(), place_text(p), place_text(r));
    }
    for (std::size_t i = 1; i < points.size(); ++i) {
      const auto& a = points[i - 1];
      const auto& b = points[i];
      const double d = std::hypot(b.x - a.x, b.y - a.y);
      if (d <= kStill) continue;
      const double v = b.t > a.t ? d / (static_cast<double>(b.t - a.t) * 1e-9)
                                 : std::numeric_limits<double>::infinity();
      if (v > params_.max_speed * (1 + kSpeedTolerance)) {
        return fmt::format(
            "section {}: the leg from {} at {} ns to {} at {} ns needs {:.3f} m/s, more than "
            "max_speed {} m/s",
            k, place_text({a.x, a.y}), a.t, place_text({b.x, b.y}), b.t, v, params_.max_speed);
      }
    }
  }
  for (const auto& j : request.jobs_added()) {
    if (j.id().empty()) return "a job added has no id";
    if (j.end_ns() < j.start_ns()) {
      return fmt::format("job '{}' ends at {} ns, before it starts at {} ns", j.id(), j.end_ns(),
                         j.start_ns());
    }
  }
  return {};
}

void RobotSim::drop_undecided(Cycle& cycle, Stamp now) {
  for (auto it = pending_.begin(); it != pending_.end();) {
    Stamp begins = now;
    for (const auto& s : it->second.sections()) begins = std::min(begins, s.from_ns());
    if (now - begins <= params_.undecided_for.count()) {
      ++it;
      continue;
    }
    cycle.log().info(
        "robot '{}' drops transaction {}: no commit or abort came, and it began "
        "{:.1f} s ago",
        name_, it->first, static_cast<double>(now - begins) * 1e-9);
    it = pending_.erase(it);
  }
}

CommandAnswer RobotSim::propose(const Trajectory& request) {
  const Stamp arrived = command_time();
  break_down_if_due(arrived);
  auto answer = [&] {
    if (auto why = refusal(request, arrived); !why.empty()) return CommandAnswer::refuse(why);
    // One draw per acceptable proposal, so a seed gives the same answers to the same proposals.
    const double u = static_cast<double>(random_() >> 11) * 0x1.0p-53;  // uniform in [0, 1)
    if (u < params_.nak_probability) {
      return CommandAnswer::refuse(
          fmt::format("refused by fault injection (nak_probability {})", params_.nak_probability));
    }
    const bool replaces = pending_.contains(request.transaction());
    pending_[request.transaction()] = request;
    return CommandAnswer::accept(fmt::format(
        "transaction {} pending: {} section(s), {} job(s) added, {} removed{}",
        request.transaction(), request.sections().size(), request.jobs_added().size(),
        request.jobs_removed().size(), replaces ? " (replaces its earlier proposal)" : ""));
  }();
  if (params_.ack_delay_ms > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(params_.ack_delay_ms));
  }
  return answer;
}

std::string RobotSim::decision_refusal(const TransactionDecision& decision) const {
  if (decision.robot() != name_) {
    return fmt::format("the decision is for robot '{}', not '{}'", decision.robot(), name_);
  }
  if (pending_.contains(decision.transaction())) return {};
  std::vector<std::uint64_t> ids;
  for (const auto& [id, p] : pending_) ids.push_back(id);
  return fmt::format(
      "no proposal of transaction {} is pending ({})", decision.transaction(),
      ids.empty() ? std::string("none is") : fmt::format("pending: {}", fmt::join(ids, ", ")));
}

CommandAnswer RobotSim::commit(const TransactionDecision& decision) {
  const Stamp now = command_time();
  break_down_if_due(now);
  if (auto why = decision_refusal(decision); !why.empty()) return CommandAnswer::refuse(why);
  if (broken_) {
    return CommandAnswer::refuse(
        fmt::format("robot '{}' is broken: {}; it cannot drive transaction {}", name_, fault_,
                    decision.transaction()));
  }
  const auto p = pending_.extract(decision.transaction());
  const Trajectory& t = p.mapped();
  std::string late;
  for (const auto k : by_start(t)) {
    const auto& s = t.sections()[k];
    committed_.splice(points_of(s), s.from_ns(), s.to_ns(), s.open_end(), t.transaction());
    if (s.from_ns() <= now && late.empty()) {
      late = fmt::format("; late: section {} began {:.1f} ms before the commit arrived", k,
                         ms_between(s.from_ns(), now));
    }
  }
  for (const auto& id : t.jobs_removed()) jobs_.erase(id);
  for (const auto& j : t.jobs_added()) jobs_[j.id()] = j;
  return CommandAnswer::accept(fmt::format(
      "transaction {} committed: {} section(s), {} job(s) added, {} removed{}", t.transaction(),
      t.sections().size(), t.jobs_added().size(), t.jobs_removed().size(), late));
}

CommandAnswer RobotSim::abort(const TransactionDecision& decision) {
  if (auto why = decision_refusal(decision); !why.empty()) return CommandAnswer::refuse(why);
  pending_.erase(decision.transaction());
  return CommandAnswer::accept(
      fmt::format("transaction {} aborted: its proposal is dropped", decision.transaction()));
}

// What the robot has committed from now on, as a Trajectory in YAML: one open-ended section from
// now (its place now, then the committed waypoints after now) and the jobs not yet done. Pending
// proposals are not part of it. A broken robot stands and works nothing.
CommandAnswer RobotSim::committed_plan(const CommittedPlanQuery& query) {
  const Stamp now = command_time();
  break_down_if_due(now);
  if (query.robot() != name_) {
    return CommandAnswer::refuse(
        fmt::format("the query is for robot '{}', not '{}'", query.robot(), name_));
  }
  Trajectory plan;
  plan.robot(name_);
  TrajectorySection s;
  s.from_ns(now);
  s.open_end(true);
  for (const auto& p : committed_.from(now)) {
    SwarmWaypoint w;
    w.x(p.x);
    w.y(p.y);
    w.t_ns(p.t);
    s.waypoints().push_back(w);
  }
  s.to_ns(s.waypoints().back().t_ns());
  plan.sections().push_back(std::move(s));
  if (!broken_) {
    for (const auto& [id, job] : jobs_) {
      if (job.end_ns() > now) plan.jobs_added().push_back(job);
    }
    std::stable_sort(
        plan.jobs_added().begin(), plan.jobs_added().end(),
        [](const RobotJob& a, const RobotJob& b) { return a.start_ns() < b.start_ns(); });
  }
  return CommandAnswer::accept(to_yaml(plan));
}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::RobotSim, "robot_sim")
