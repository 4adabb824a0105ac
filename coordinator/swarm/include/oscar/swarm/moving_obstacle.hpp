#pragma once
/// @file A polygon translated along a piecewise-linear trajectory (seed 002 §4.3, O^m).

#include "oscar/swarm/geometry.hpp"
#include "oscar/swarm/trajectory.hpp"

namespace oscar::swarm {

/// A moving obstacle: `shape` (relative to the trajectory point) translated along `trajectory`.
/// It exists during [trajectory.start_time(), trajectory.end_time()] only; a node's trajectory
/// used as an obstacle is extended to kForever by its owner.
struct MovingObstacle {
  Polygon shape;
  Trajectory trajectory;
};

}  // namespace oscar::swarm
