#pragma once
/// @file The world the swarm moves in (seed 002 §4.1, §5.2 World).

#include <vector>

#include "oscar/swarm/moving_obstacle.hpp"

namespace oscar::swarm {

/// Static polygons O^s and moving polygons O^m (seed §4.3). Nodes are not part of the world.
struct World {
  std::vector<Polygon> static_obstacles;
  std::vector<MovingObstacle> dynamic_obstacles;
};

}  // namespace oscar::swarm
