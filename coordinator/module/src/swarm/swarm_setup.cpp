// The `coordinator: swarm:` section of a system file (docs/swarm.md, "The live swarm").
#include <fmt/format.h>
#include <cmath>
#include <stdexcept>

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
      {"robots", "world", "frozen_horizon_ms", "ack_timeout_ms", "replan_attempts", "lost_after_ms",
       "location_samples", "dependency_margin_s", "wait_threshold_s", "seed"});
  SwarmSetup s;
  s.where = yaml_where(file, node);
  if (const auto robots = node["robots"]) {
    if (!robots.IsSequence()) fail(file, robots, "swarm.robots: expected a list of kernel names");
    for (const auto& r : robots) {
      const auto name = r.IsScalar() ? r.Scalar() : std::string();
      const auto* m = host_of(system, name);
      if (!m) {
        fail(file, r, fmt::format("swarm.robots: no kernel named '{}' in the system", name));
      }
      s.robots.push_back({name, m->spec.name});
    }
  } else {
    for (const auto& m : system.modules) {
      for (const auto& k : m.spec.kernels) {
        if (k.type == "robot_sim") s.robots.push_back({k.name, m.spec.name});
      }
    }
  }
  if (s.robots.empty()) {
    fail(file, node,
         "coordinator.swarm: no robots (name them in robots:, or add robot_sim kernels)");
  }
  if (const auto world = node["world"]) {
    s.world = swarm::parse_world(world, file);
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
