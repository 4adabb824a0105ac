// The `coordinator: swarm:` section of a system file (docs/swarm.md, "The live swarm").
#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "live_world.hpp"
#include "oscar/coordinator/swarm_setup.hpp"
#include "oscar/module_spec.hpp"
#include "oscar/swarm/problem.hpp"

namespace oscar::coordinator {

namespace {

[[noreturn]] void fail(const std::string& file, const YAML::Node& node, const std::string& m) {
  throw std::invalid_argument(fmt::format("{}: {}", yaml_where(file, node), m));
}

double number(const std::string& file, const YAML::Node& node, const std::string& what, double lo,
              double hi) {
  double v = NAN;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
  }
  if (!std::isfinite(v) || v < lo || v > hi) {
    fail(file, node,
         fmt::format(
             "swarm.{}: expected a number in [{}, {}], got '{}'", what, lo, hi,
             node.IsScalar() ? node.Scalar() : "a " + std::string(node.IsMap() ? "map" : "list")));
  }
  return v;
}

int integer(const std::string& file, const YAML::Node& node, const std::string& what, int lo,
            int hi) {
  const double v = number(file, node, what, lo, hi);
  if (v != std::floor(v)) fail(file, node, fmt::format("swarm.{}: expected a whole number", what));
  return static_cast<int>(v);
}

std::chrono::milliseconds millis(const std::string& file, const YAML::Node& node,
                                 const std::string& what) {
  return std::chrono::milliseconds(std::llround(number(file, node, what, 1, 3'600'000)));
}

// The module hosting kernel `name`, if the system has one.
const SystemModule* host_of(const SystemSpec& system, const std::string& name,
                            std::string* type = nullptr) {
  for (const auto& m : system.modules) {
    for (const auto& k : m.spec.kernels) {
      if (k.name != name) continue;
      if (type) *type = k.type;
      return &m;
    }
  }
  return nullptr;
}

// Kernels named in `key` (a list), or every kernel of `type` when the key is left out.
std::vector<SwarmSetup::Robot> kernels(const SystemSpec& system, const YAML::Node& node,
                                       const std::string& key, const std::string& type) {
  std::vector<SwarmSetup::Robot> result;
  const std::string& file = system.file;
  if (const auto list = node[key]) {
    if (!list.IsSequence())
      fail(file, list, fmt::format("swarm.{}: expected a list of kernel names", key));
    for (const auto& r : list) {
      const auto name = r.IsScalar() ? r.Scalar() : std::string();
      const auto* m = host_of(system, name);
      if (!m) {
        fail(file, r, fmt::format("swarm.{}: no kernel named '{}' in the system", key, name));
      }
      result.push_back({name, m->spec.name});
    }
    return result;
  }
  for (const auto& m : system.modules) {
    for (const auto& k : m.spec.kernels) {
      if (k.type == type) result.push_back({k.name, m.spec.name});
    }
  }
  return result;
}

std::vector<double> numbers(const std::string& file, const YAML::Node& n, std::size_t count,
                            const std::string& what) {
  std::vector<double> v;
  if (n.IsSequence() && n.size() == count) {
    for (const auto& x : n) {
      try {
        v.push_back(x.as<double>());
      } catch (const YAML::Exception&) {
        break;
      }
    }
  }
  if (v.size() != count ||
      !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); })) {
    fail(file, n,
         fmt::format("{}: expected [{}] of finite numbers", what, count == 2 ? "x, y" : "x, y, t"));
  }
  return v;
}

// `world:`: static polygons as a problem file has them; moving obstacles go round loops in Unix
// time, as the safety monitor's moving_obstacles.
std::vector<SwarmObstacle> parse_live_world(const std::string& file, const YAML::Node& node) {
  if (!node.IsMap()) fail(file, node, "swarm.world: expected a map (static, dynamic)");
  check_yaml_keys(node, file, "swarm.world", {"static", "dynamic"});
  LiveWorld world;
  if (const auto st = node["static"]) {
    YAML::Node only;
    only["static"] = st;
    const auto polygons = swarm::parse_world(only, file).static_obstacles;
    for (std::size_t i = 0; i < polygons.size(); ++i) {
      SwarmObstacle o;
      o.name(fmt::format("static[{}]", i));
      for (const auto& p : swarm::vertices(polygons[i])) {
        o.shape().x().push_back(p.x());
        o.shape().y().push_back(p.y());
      }
      world.add(std::move(o));
    }
  }
  if (const auto dyn = node["dynamic"]) {
    if (!dyn.IsSequence()) fail(file, dyn, "world.dynamic: expected a list of {name, shape, loop}");
    for (std::size_t i = 0; i < dyn.size(); ++i) {
      const auto e = dyn[i];
      const std::string what = fmt::format("world.dynamic[{}]", i);
      if (!e.IsMap()) fail(file, e, what + ": expected a map {name, shape, loop}");
      if (e["trajectory"]) {
        fail(file, e["trajectory"],
             what +
                 ": a running swarm's moving obstacle goes round a loop in Unix time: "
                 "loop: [[x, y, t], ...] from t = 0 to its period, ending where it starts (it "
                 "starts again at every multiple of the period since the Unix epoch), not a "
                 "trajectory");
      }
      check_yaml_keys(e, file, what, {"name", "shape", "loop"});
      SwarmObstacle o;
      o.name(e["name"] && e["name"].IsScalar() ? e["name"].Scalar() : what);
      const auto shape = e["shape"];
      if (!shape || !shape.IsSequence()) fail(file, e, what + ".shape: expected [[x, y], ...]");
      for (const auto& p : shape) {
        const auto xy = numbers(file, p, 2, what + ".shape");
        o.shape().x().push_back(xy[0]);
        o.shape().y().push_back(xy[1]);
      }
      const auto loop = e["loop"];
      if (!loop || !loop.IsSequence()) fail(file, e, what + ".loop: expected [[x, y, t], ...]");
      for (const auto& p : loop) {
        const auto xyt = numbers(file, p, 3, what + ".loop");
        SwarmWaypoint w;
        w.x(xyt[0]);
        w.y(xyt[1]);
        w.t_ns(std::llround(xyt[2] * 1e9));
        o.path().push_back(w);
      }
      if (!o.path().empty()) o.loop_ns(o.path().back().t_ns());
      try {
        world.add(std::move(o));
      } catch (const std::invalid_argument& ex) {
        fail(file, e, fmt::format("{}: {}", what, ex.what()));
      }
    }
  }
  return world.obstacles();
}

}  // namespace

std::optional<SwarmSetup> SwarmSetup::from(const SystemSpec& system) {
  // Not `!swarm`: a default YAML::Node is a defined null, true as a bool.
  if (!system.coordinator || !system.coordinator->swarm || system.coordinator->swarm.IsNull()) {
    return std::nullopt;
  }
  const YAML::Node node = system.coordinator->swarm;
  const std::string& file = system.file;
  if (!node.IsMap()) fail(file, node, "coordinator.swarm: expected a map (robots, world, ...)");
  check_yaml_keys(
      node, file, "coordinator.swarm",
      {"robots", "monitors", "world", "frozen_horizon_ms", "ack_timeout_ms", "replan_attempts",
       "lost_after_ms", "location_samples", "dependency_margin_s", "wait_threshold_s", "seed"});
  SwarmSetup s;
  s.where = yaml_where(file, node);
  s.robots = kernels(system, node, "robots", "robot_sim");
  s.monitors = kernels(system, node, "monitors", "safety_monitor");
  if (s.robots.empty()) {
    fail(file, node,
         "coordinator.swarm: no robots (name them in robots:, or add robot_sim kernels)");
  }
  if (const auto world = node["world"]) {
    s.world = parse_live_world(file, world);
  }
  auto& st = s.settings;
  st.frozen_horizon = 1.0;
  if (const auto n = node["frozen_horizon_ms"]) {
    st.frozen_horizon = number(file, n, "frozen_horizon_ms", 0, 3'600'000) / 1000;
  }
  if (const auto n = node["ack_timeout_ms"]) s.ack_timeout = millis(file, n, "ack_timeout_ms");
  if (const auto n = node["lost_after_ms"]) s.lost_after = millis(file, n, "lost_after_ms");
  if (const auto n = node["replan_attempts"]) {
    s.replan_attempts = integer(file, n, "replan_attempts", 0, 100);
  }
  if (const auto n = node["location_samples"]) {
    st.location_samples = integer(file, n, "location_samples", 1, 10000);
  }
  if (const auto n = node["dependency_margin_s"]) {
    st.dependency_margin = number(file, n, "dependency_margin_s", 0, 1e5);
  }
  if (const auto n = node["wait_threshold_s"]) {
    st.wait_threshold = number(file, n, "wait_threshold_s", 0, 1e5);
  }
  if (const auto n = node["seed"])
    st.seed = static_cast<unsigned>(integer(file, n, "seed", 0, 1 << 30));
  if (std::chrono::duration<double>(s.ack_timeout).count() * 2 > st.frozen_horizon) {
    fail(file, node,
         fmt::format("coordinator.swarm: frozen_horizon_ms ({}) must cover a proposal and its "
                     "commit, at least 2 × ack_timeout_ms ({}): a robot would be told to change "
                     "what it already drives",
                     st.frozen_horizon * 1000, s.ack_timeout.count()));
  }
  return s;
}

}  // namespace oscar::coordinator
