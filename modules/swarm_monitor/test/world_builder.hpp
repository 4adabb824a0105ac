#pragma once
/// @file Builds the coordinator's world (oscar::SwarmWorld) for the safety monitor's tests.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <oscar/swarm_types.hpp>

namespace oscar::modules::world_builder {

/// A polygon from its vertices (x, y).
inline SwarmArea area(const std::vector<std::pair<double, double>>& vertices) {
  SwarmArea a;
  for (const auto& [x, y] : vertices) {
    a.x().push_back(x);
    a.y().push_back(y);
  }
  return a;
}

inline SwarmWaypoint waypoint(double x, double y, std::int64_t t_ns) {
  SwarmWaypoint w;
  w.x(x);
  w.y(y);
  w.t_ns(t_ns);
  return w;
}

/// Static without a path; moving along `path` (in Unix time, or a loop when loop_ns > 0).
inline SwarmObstacle obstacle(const std::string& name, const SwarmArea& shape,
                              const std::vector<SwarmWaypoint>& path = {}, std::int64_t loop_ns = 0,
                              std::int64_t since_ns = 0) {
  SwarmObstacle o;
  o.name(name);
  o.shape(shape);
  o.path(path);
  o.loop_ns(loop_ns);
  o.since_ns(since_ns);
  return o;
}

inline SwarmWorld world(const std::vector<SwarmObstacle>& obstacles) {
  SwarmWorld w;
  w.obstacles(obstacles);
  return w;
}

}  // namespace oscar::modules::world_builder
