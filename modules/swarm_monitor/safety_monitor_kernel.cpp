#include "safety_monitor_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <regex>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <oscar/kernel_registry.hpp>

namespace oscar::modules {
namespace {

using safety::LoopPoint;
using safety::Point;
using safety::Polygon;

constexpr Stamp kStubEvery = 1'000'000'000;  // stub mode: a made-up violation at most this often

std::invalid_argument param_error(const std::string& param, const std::string& what) {
  return std::invalid_argument(fmt::format("safety_monitor: parameter '{}': {}", param, what));
}

YAML::Node load_yaml(const std::string& param, const std::string& text) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw param_error(param, fmt::format("not YAML: {}", e.msg));
  }
}

/// A sequence of `n` finite numbers, or nothing.
std::optional<std::vector<double>> numbers(const YAML::Node& node, std::size_t n) {
  if (!node.IsSequence() || node.size() != n) return std::nullopt;
  std::vector<double> out;
  for (const auto& item : node) {
    double v = 0;
    if (!item.IsScalar() || !YAML::convert<double>::decode(item, v) || !std::isfinite(v)) {
      return std::nullopt;
    }
    out.push_back(v);
  }
  return out;
}

/// A polygon [[x, y], ...]: at least three vertices, finite, of non-zero area.
Polygon parse_polygon(const std::string& param, const std::string& what, const YAML::Node& node) {
  if (!node.IsSequence() || node.size() < 3) {
    throw param_error(param, fmt::format("{} must be a list of at least 3 vertices [x, y]", what));
  }
  Polygon polygon;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const auto xy = numbers(node[i], 2);
    if (!xy) {
      throw param_error(param,
                        fmt::format("{}: vertex {} is not [x, y] of finite numbers (m)", what, i));
    }
    polygon.push_back({(*xy)[0], (*xy)[1]});
  }
  if (safety::signed_area(polygon) == 0) {
    throw param_error(param, fmt::format("{} has no area", what));
  }
  return polygon;
}

std::string point_text(Point p) { return fmt::format("({:.3f}, {:.3f})", p.x, p.y); }

Stamp stamp_of(const RobotState& s, Stamp fallback) {
  const auto t = generation_stamp(s.header());
  return t ? t : fallback;
}

std::string name_of(const RobotState& s, const std::string& input) {
  return s.robot().empty() ? input : s.robot();
}

}  // namespace

void SafetyMonitor::Params::describe(ParamSpec& spec) {
  spec.field("inputs", inputs,
             "robot inputs to declare besides those the configuration wires: 'name, ...'")
      .fixed();
  spec.field("static_obstacles", static_obstacles,
             "static obstacles, YAML text: '[ [[x, y], ...], ... ]' (polygons, m)")
      .fixed();
  spec.field("moving_obstacles", moving_obstacles,
             "moving obstacles, YAML text: '[ {shape: [[x, y], ...], loop: [[x, y, t], ...]} ]' "
             "(shape around the obstacle's origin, m; t in s from 0 to the period; first and "
             "last point equal; at Unix time T the loop time is T mod period)")
      .fixed();
  spec.field("distance_tolerance", distance_tolerance,
             "how far (m) a robot's disc may reach into another's or into an obstacle")
      .at_least(0);
  spec.field("job_tolerance", job_tolerance,
             "how far (m) a robot working a job may be from the job's place")
      .at_least(0);
  spec.field("max_extrapolation", max_extrapolation,
             "another robot's state is extrapolated to the checked state's stamp with its speed "
             "and heading if their stamps differ by at most this (a broken robot: any)")
      .at_least(0);
}

std::vector<std::string> SafetyMonitor::parse_inputs(const std::string& text) {
  static const std::regex name(R"(\s*([A-Za-z_][A-Za-z0-9_]*)\s*)");
  static const std::regex blank(R"(\s*)");
  std::vector<std::string> out;
  if (std::regex_match(text, blank)) return out;
  std::set<std::string> seen;
  std::size_t start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    const auto item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    std::smatch m;
    if (!std::regex_match(item, m, name)) {
      throw param_error("inputs", fmt::format("'{}' is not an input name (e.g. 'r1, r2')", item));
    }
    if (!seen.insert(m[1]).second) {
      throw param_error("inputs", fmt::format("input '{}' is named twice", m[1].str()));
    }
    out.push_back(m[1]);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

std::vector<safety::StaticObstacle> SafetyMonitor::parse_static_obstacles(const std::string& text) {
  const std::string param = "static_obstacles";
  const auto root = load_yaml(param, text);
  std::vector<safety::StaticObstacle> out;
  if (root.IsNull()) return out;
  if (!root.IsSequence()) {
    throw param_error(param, "must be a list of polygons, each a list of [x, y]");
  }
  for (std::size_t i = 0; i < root.size(); ++i) {
    // Unnamed: its violations name it by its index, as they always have.
    out.push_back({"", parse_polygon(param, fmt::format("obstacle {}", i), root[i]), 0});
  }
  return out;
}

std::vector<safety::MovingObstacle> SafetyMonitor::parse_moving_obstacles(const std::string& text) {
  const std::string param = "moving_obstacles";
  const auto root = load_yaml(param, text);
  std::vector<safety::MovingObstacle> out;
  if (root.IsNull()) return out;
  if (!root.IsSequence()) {
    throw param_error(param, "must be a list of {shape: [[x, y], ...], loop: [[x, y, t], ...]}");
  }
  for (std::size_t i = 0; i < root.size(); ++i) {
    const auto what = fmt::format("obstacle {}", i);
    const auto& node = root[i];
    if (!node.IsMap()) {
      throw param_error(param, fmt::format("{} must be a map {{shape: ..., loop: ...}}", what));
    }
    for (const auto& kv : node) {
      const auto key = kv.first.Scalar();
      if (key != "shape" && key != "loop") {
        throw param_error(param,
                          fmt::format("{}: unknown key '{}' (it has shape and loop)", what, key));
      }
    }
    safety::MovingObstacle o;
    o.shape = parse_polygon(param, what + ": shape", node["shape"]);
    const auto loop = node["loop"];
    if (!loop || !loop.IsSequence() || loop.size() < 2) {
      throw param_error(
          param, fmt::format("{}: loop must be a list of at least 2 points [x, y, t]", what));
    }
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const auto xyt = numbers(loop[k], 3);
      if (!xyt) {
        throw param_error(param, fmt::format("{}: loop point {} is not [x, y, t] of finite "
                                             "numbers (m, m, s)",
                                             what, k));
      }
      const LoopPoint p{(*xyt)[0], (*xyt)[1], (*xyt)[2]};
      if (k == 0 && p.t != 0) {
        throw param_error(param, fmt::format("{}: the loop starts at t = 0, not {}", what, p.t));
      }
      if (k > 0 && p.t < o.path.back().t) {
        throw param_error(param, fmt::format("{}: loop point {} goes back in time ({} < {})", what,
                                             k, p.t, o.path.back().t));
      }
      o.path.push_back(p);
    }
    const auto& first = o.path.front();
    const auto& last = o.path.back();
    if (last.t <= 0) {
      throw param_error(param, fmt::format("{}: the loop's period (its last t) must be > 0", what));
    }
    if (first.x != last.x || first.y != last.y) {
      throw param_error(
          param, fmt::format("{}: the loop's first and last points differ: {} "
                             "and {} (a loop ends where it starts)",
                             what, point_text({first.x, first.y}), point_text({last.x, last.y})));
    }
    o.period_ns = std::llround(last.t * 1e9);
    out.push_back(std::move(o));
  }
  return out;
}

SafetyMonitor::SafetyMonitor(KernelSetup& setup)
    : out_(setup.output<SafetyViolation>("violations", {.depth = 64, .reliable = true})) {
  setup.params(params_);
  obstacles_.static_obstacles = parse_static_obstacles(params_.static_obstacles);
  obstacles_.moving_obstacles = parse_moving_obstacles(params_.moving_obstacles);
  setup.command<SwarmWorld>("world", [this](const SwarmWorld& w) { return set_world(w); });
  std::set<std::string> names;
  for (const auto& name : setup.configured_inputs()) names.insert(name);
  for (const auto& name : parse_inputs(params_.inputs)) names.insert(name);
  if (names.empty()) {
    throw std::invalid_argument(
        "safety_monitor: no robots to watch: wire one input per robot in the kernel's inputs: "
        "(e.g. inputs: { r1: r1/state, r2: r2/state }) or name them in parameter 'inputs'");
  }
  for (const auto& name : names) {
    robots_.push_back({name, &setup.input<RobotState>(name, {.depth = 64})});
  }
  for (const auto* kind : kKinds) counts_[kind] = 0;
}

CommandAnswer SafetyMonitor::set_world(const SwarmWorld& world) {
  safety::Obstacles obstacles;
  try {
    obstacles = safety::obstacles_of(world);
  } catch (const std::invalid_argument& e) {
    return CommandAnswer::refuse(e.what());
  }
  // A violation of an obstacle that left the world has ended; one of an obstacle that stays
  // (the same kind and name) goes on, so that sending the same world again reports nothing anew.
  std::set<std::string> labels;  // "kind|label"
  for (std::size_t k = 0; k < obstacles.static_obstacles.size(); ++k) {
    labels.insert("static_obstacle|" +
                  safety::obstacle_label(obstacles.static_obstacles[k].name, k));
  }
  for (std::size_t k = 0; k < obstacles.moving_obstacles.size(); ++k) {
    labels.insert("moving_obstacle|" +
                  safety::obstacle_label(obstacles.moving_obstacles[k].name, k));
  }
  std::size_t ended = 0;
  for (auto it = conditions_.begin(); it != conditions_.end();) {
    // Keys of obstacles are "kind|input|label"; input names have no '|'.
    const auto kind_end = it->first.find('|');
    const auto input_end = it->first.find('|', kind_end + 1);
    const auto kind = it->first.substr(0, kind_end);
    const bool obstacle = kind == "static_obstacle" || kind == "moving_obstacle";
    if (obstacle && !labels.count(kind + "|" + it->first.substr(input_end + 1))) {
      ended += it->second.active ? 1 : 0;
      it = conditions_.erase(it);
    } else {
      ++it;
    }
  }
  obstacles_ = std::move(obstacles);
  return CommandAnswer::accept(fmt::format(
      "world: {} static, {} moving obstacles; violations ended with their obstacles: {}",
      obstacles_.static_obstacles.size(), obstacles_.moving_obstacles.size(), ended));
}

std::uint64_t SafetyMonitor::count(const std::string& kind) const {
  const auto it = counts_.find(kind);
  return it == counts_.end() ? 0 : it->second;
}

void SafetyMonitor::process(Cycle& cycle) {
  // Every state that arrived since the last cycle, of all robots, in the order of their stamps.
  struct Arrived {
    std::size_t robot;
    Stamp t;
    std::shared_ptr<const RobotState> state;
  };
  std::vector<Arrived> arrived;
  for (std::size_t i = 0; i < robots_.size(); ++i) {
    for (auto& r : robots_[i].in->take_new()) {
      arrived.push_back({i, stamp_of(*r.cue, cycle.now()), r.cue});
    }
  }
  std::stable_sort(arrived.begin(), arrived.end(),
                   [](const Arrived& a, const Arrived& b) { return a.t < b.t; });
  for (const auto& a : arrived) check(cycle, a.robot, *a.state);
}

std::optional<SafetyMonitor::Place> SafetyMonitor::place_of(std::size_t robot, Stamp t) const {
  auto state = robots_[robot].in->nearest(t);
  if (!state) return std::nullopt;
  const Stamp from = stamp_of(*state, t);
  Place p;
  p.dt_s = static_cast<double>(t - from) * 1e-9;
  p.at = {state->x(), state->y()};
  if (!state->broken()) {  // a broken robot stands where it broke down, for good
    if (std::abs(t - from) > params_.max_extrapolation.count()) return std::nullopt;
    p.at.x += state->speed() * std::cos(state->heading()) * p.dt_s;
    p.at.y += state->speed() * std::sin(state->heading()) * p.dt_s;
  }
  p.state = std::move(state);
  return p;
}

void SafetyMonitor::check(Cycle& cycle, std::size_t robot, const RobotState& state) {
  const Stamp t = stamp_of(state, cycle.now());
  const auto& input = robots_[robot].input;
  const auto name = name_of(state, input);
  const Point at{state.x(), state.y()};
  const double r = state.radius();
  const double tol = params_.distance_tolerance;
  const auto& header = state.header();

  // (1) Every other robot, where it is at this state's time.
  for (std::size_t j = 0; j < robots_.size(); ++j) {
    if (j == robot) continue;
    const auto other = place_of(j, t);
    if (!other) continue;  // no state near enough in time: this pair is not compared now
    const auto other_name = name_of(*other->state, robots_[j].input);
    const double d = std::hypot(other->at.x - at.x, other->at.y - at.y);
    const double r2 = other->state->radius();
    const bool first = input < robots_[j].input;
    const auto key = fmt::format("distance|{}|{}", first ? input : robots_[j].input,
                                 first ? robots_[j].input : input);
    std::optional<Finding> f;
    if (d < r + r2 - tol) {
      const auto how = other->state->broken() ? std::string(" (broken down, standing)")
                       : other->dt_s == 0
                           ? std::string()
                           : fmt::format(" (its state of {:+.3f} s extrapolated with {:.3f} m/s)",
                                         -other->dt_s, other->state->speed());
      f = Finding{"distance",
                  first ? std::vector{name, other_name} : std::vector{other_name, name},
                  "",
                  fmt::format("{} and {} are {:.3f} m apart, less than their radii {:.3f} + {:.3f} "
                              "= {:.3f} m (tolerance {} m): {} at {}, {} at {}{}",
                              name, other_name, d, r, r2, r + r2, tol, name, point_text(at),
                              other_name, point_text(other->at), how),
                  {(at.x + other->at.x) / 2, (at.y + other->at.y) / 2}};
    }
    evaluate(cycle, key, t, header, std::move(f));
  }

  // (2) Static and moving obstacles.
  check_obstacles(cycle, robot, state);

  // (3) The job it works: at its place, within its windows.
  const auto& job = state.job();
  const auto job_prefix = fmt::format("job|{}|", input);
  const auto place_key = job.id().empty() ? "" : job_prefix + job.id() + "|place";
  const auto time_key = job.id().empty() ? "" : job_prefix + job.id() + "|time";
  // Violations of jobs it no longer works have ended.
  for (auto it = conditions_.lower_bound(job_prefix);
       it != conditions_.end() && it->first.starts_with(job_prefix);) {
    if (it->first == place_key || it->first == time_key) {
      ++it;
      continue;
    }
    if (it->second.active) cycle.log().info("{} ended: {} works another job", it->first, name);
    it = conditions_.erase(it);
  }
  if (job.id().empty()) return;
  const double d = std::hypot(at.x - job.x(), at.y - job.y());
  std::optional<Finding> f;
  if (d > params_.job_tolerance) {
    f = Finding{"job",
                {name},
                job.id(),
                fmt::format("{} works job {} at {}, {:.3f} m from the job's place {}, farther "
                            "than the job tolerance {} m",
                            name, job.id(), point_text(at), d, point_text({job.x(), job.y()}),
                            params_.job_tolerance),
                at};
  }
  evaluate(cycle, place_key, t, header, std::move(f));

  // A bound of 0 is none given.
  std::vector<std::string> late;
  const auto seconds = [](Stamp dt) { return static_cast<double>(dt) * 1e-9; };
  if (job.earliest_start_ns() && t < job.earliest_start_ns()) {
    late.push_back(fmt::format("{:.3f} s before the job's earliest start",
                               seconds(job.earliest_start_ns() - t)));
  }
  if (job.latest_finish_ns() && t > job.latest_finish_ns()) {
    late.push_back(
        fmt::format("{:.3f} s after the job's latest finish", seconds(t - job.latest_finish_ns())));
  }
  if (job.start_ns() && t < job.start_ns()) {
    late.push_back(fmt::format("{:.3f} s before its own start", seconds(job.start_ns() - t)));
  }
  if (job.end_ns() && t > job.end_ns()) {
    late.push_back(fmt::format("{:.3f} s after its own end", seconds(t - job.end_ns())));
  }
  f.reset();
  if (!late.empty()) {
    f = Finding{"job",
                {name},
                job.id(),
                fmt::format("{} works job {} at t = {} ns, {} (the job's window [{}, {}] ns, "
                            "its own [{}, {}] ns)",
                            name, job.id(), t, fmt::join(late, ", "), job.earliest_start_ns(),
                            job.latest_finish_ns(), job.start_ns(), job.end_ns()),
                at};
  }
  evaluate(cycle, time_key, t, header, std::move(f));
}

void SafetyMonitor::check_obstacles(Cycle& cycle, std::size_t robot, const RobotState& state) {
  const Stamp t = stamp_of(state, cycle.now());
  const auto& input = robots_[robot].input;
  const auto name = name_of(state, input);
  const Point at{state.x(), state.y()};
  const double r = state.radius();
  const double tol = params_.distance_tolerance;
  const auto& header = state.header();

  // Static obstacles. One the coordinator added for later (since_ns) does not count for states
  // stamped before then: a robot may legally be inside it until then.
  for (std::size_t k = 0; k < obstacles_.static_obstacles.size(); ++k) {
    const auto& o = obstacles_.static_obstacles[k];
    const auto label = safety::obstacle_label(o.name, k);
    std::optional<Finding> f;
    const double clearance = safety::disc_clearance(o.polygon, at, r);
    if (o.counts_at(t) && clearance < -tol) {
      f = Finding{"static_obstacle",
                  {name},
                  "",
                  fmt::format("{} (radius {:.3f} m) at {} reaches {:.3f} m into static obstacle "
                              "{} (centre {}, {:.3f} m from its edge; tolerance {} m)",
                              name, r, point_text(at), -clearance, label,
                              safety::contains(o.polygon, at) ? "inside" : "outside",
                              safety::distance_to_edges(o.polygon, at), tol),
                  at};
    }
    evaluate(cycle, fmt::format("static_obstacle|{}|{}", input, label), t, header, std::move(f));
  }

  // Moving obstacles, where their paths have them at this state's time (a path driven once: only
  // while it lasts), from since_ns on.
  for (std::size_t k = 0; k < obstacles_.moving_obstacles.size(); ++k) {
    const auto& o = obstacles_.moving_obstacles[k];
    const auto label = safety::obstacle_label(o.name, k);
    const auto origin = o.origin_at(t);
    std::optional<Finding> f;
    if (origin) {
      const auto polygon = safety::translated(o.shape, *origin);
      const double clearance = safety::disc_clearance(polygon, at, r);
      if (clearance < -tol) {
        const auto when =
            o.period_ns > 0
                ? fmt::format("loop time {:.3f} s of {:.3f} s", o.path_time_s(t),
                              static_cast<double>(o.period_ns) * 1e-9)
                : fmt::format("path time {:.3f} s of {:.3f} s", o.path_time_s(t), o.path.back().t);
        f = Finding{
            "moving_obstacle",
            {name},
            "",
            fmt::format("{} (radius {:.3f} m) at {} reaches {:.3f} m into moving obstacle "
                        "{} at {}, its origin at {} (centre {}, {:.3f} m from its edge; "
                        "tolerance {} m)",
                        name, r, point_text(at), -clearance, label, when, point_text(*origin),
                        safety::contains(polygon, at) ? "inside" : "outside",
                        safety::distance_to_edges(polygon, at), tol),
            at};
      }
    }
    evaluate(cycle, fmt::format("moving_obstacle|{}|{}", input, label), t, header, std::move(f));
  }
}

void SafetyMonitor::evaluate(Cycle& cycle, const std::string& key, Stamp t, const CueHeader& header,
                             std::optional<Finding> finding) {
  auto& c = conditions_[key];
  // States of different robots may arrive out of order. A judgement older than the condition's
  // last one may start a violation (none is dropped for arriving late) but not end one: the
  // newer finding stands.
  const bool late = t < c.last;
  c.last = std::max(c.last, t);
  if (finding && !c.active) {
    c.active = true;
    report(cycle, header, std::move(*finding));
  } else if (!finding && c.active && !late) {
    c.active = false;
    cycle.log().info("violation ended: {}", key);
  }
}

void SafetyMonitor::report(Cycle& cycle, const CueHeader& header, Finding finding) {
  ++counts_[finding.kind];
  ++total_;
  cycle.log().warn("violation {} ({}, {} of its kind): {}", total_, finding.kind,
                   counts_[finding.kind], finding.detail);
  SafetyViolation v;
  v.header().stamps(header.stamps());
  if (v.header().stamps().empty()) append_stamp(v.header(), cycle.now());
  append_stamp(v.header(), cycle.now());
  v.kind(std::move(finding.kind));
  v.robots(std::move(finding.robots));
  v.job(std::move(finding.job));
  v.detail(std::move(finding.detail));
  v.x(finding.at.x);
  v.y(finding.at.y);
  v.count(total_);
  out_.publish(std::move(v));
}

void SafetyMonitor::stub(Cycle& cycle) {
  for (auto& robot : robots_) (void)robot.in->take_new();  // not checked: not checked later
  if (last_stub_ && cycle.now() - last_stub_ < kStubEvery) return;
  last_stub_ = cycle.now();
  const auto* kind = kKinds[stub_count_ % std::size(kKinds)];
  ++stub_count_;
  SafetyViolation v;
  append_stamp(v.header(), cycle.now());
  v.kind(kind);
  v.robots().push_back(robots_.front().input);
  if (v.kind() == "distance" && robots_.size() > 1) v.robots().push_back(robots_[1].input);
  if (v.kind() == "job") v.job("stub");
  v.detail("stub mode: made up, nothing was checked");
  v.count(stub_count_);
  out_.publish(std::move(v));
}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::SafetyMonitor, "safety_monitor")
