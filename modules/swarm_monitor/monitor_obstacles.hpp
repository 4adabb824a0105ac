#pragma once
/// @file The obstacles the safety monitor checks robots against: from its parameters
/// (`static_obstacles`, `moving_obstacles`) or, once the coordinator speaks, from its command
/// `world` (oscar::SwarmWorld, idl/oscar/swarm.idl), which replaces them all.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <oscar/swarm_types.hpp>

#include "monitor_geometry.hpp"

namespace oscar::modules::safety {

/// A polygon that stands where it is.
struct StaticObstacle {
  std::string name;  ///< empty for one of parameter `static_obstacles`: known by its index
  Polygon polygon;
  std::int64_t since_ns = 0;  ///< counts for states stamped at or after this Unix time (0: all)

  bool counts_at(std::int64_t t_ns) const { return t_ns >= since_ns; }
};

/// A shape whose origin moves along a path, linear between its points: a loop that starts again
/// at every multiple of its period since the Unix epoch, or (period 0) a path driven once, in
/// Unix time, outside of which the obstacle is not in the world.
struct MovingObstacle {
  std::string name;  ///< empty for one of parameter `moving_obstacles`: known by its index
  Polygon shape;     ///< around the obstacle's own origin
  std::vector<LoopPoint> path;  ///< t in s: loop time, or (period 0) time since start_ns
  std::int64_t period_ns = 0;   ///< > 0: a loop of this period; 0: a path driven once
  std::int64_t start_ns = 0;    ///< period 0: Unix time of the path's first point
  std::int64_t end_ns = 0;      ///< period 0: Unix time of the path's last point
  std::int64_t since_ns = 0;    ///< counts for states stamped at or after this Unix time (0: all)

  /// The time along its path at Unix time t_ns (s): the loop time, or the time since the path's
  /// start.
  double path_time_s(std::int64_t t_ns) const;
  /// Where its origin is at Unix time t_ns; nothing where it does not count then (before
  /// since_ns, or outside [start_ns, end_ns] for a path driven once).
  std::optional<Point> origin_at(std::int64_t t_ns) const;
};

/// All the obstacles of a monitor's world.
struct Obstacles {
  std::vector<StaticObstacle> static_obstacles;
  std::vector<MovingObstacle> moving_obstacles;
};

/// How a violation's detail names an obstacle: 'name' in quotes, or its index when it has none
/// (one from the parameters).
std::string obstacle_label(const std::string& name, std::size_t index);

/// The obstacles of the coordinator's world, checked: names not empty and unique; each shape at
/// least 3 vertices, x and y of one length, finite, not meeting itself; a path's points finite,
/// its times never decreasing; a loop (loop_ns > 0) from t = 0 to t = loop_ns, ending where it
/// starts; a static obstacle (path empty) has loop_ns 0; loop_ns and since_ns not negative.
/// @throws std::invalid_argument naming the obstacle and the rule it breaks.
Obstacles obstacles_of(const SwarmWorld& world);

}  // namespace oscar::modules::safety
