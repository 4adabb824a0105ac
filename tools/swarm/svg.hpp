#pragma once
// SVG pictures for `oscar swarm plan --svg` (world view and s-t diagram).

#include <optional>
#include <string>
#include <vector>

#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm::tools {

/// What a picture of the world from above shows.
struct WorldPicture {
  struct Mark {
    Point at;
    std::string label;
  };
  struct MovingObstacle {
    Polygon shape;            ///< around its reference point
    std::vector<Point> path;  ///< where the reference point goes, drawn dashed
    Point now;                ///< where the shape is drawn
  };
  struct Robot {
    std::string id;
    std::vector<Point> path;  ///< its trajectory's places in order
    std::vector<Mark> jobs;
    /// Where it is now, drawn as a disc of its radius (red when broken) and labelled there; the
    /// label is at the path's start without one.
    std::optional<Point> now;
    double radius = 0;
    bool broken = false;
  };
  std::vector<std::string> caption;  ///< one line each, below the plot
  std::vector<Polygon> static_obstacles;
  std::vector<MovingObstacle> moving_obstacles;
  std::vector<Robot> robots;
};

std::string world_svg(const WorldPicture& picture);

/// World, committed trajectories and jobs of a plan seen from above.
std::string world_svg(const Scheduler& scheduler);

/// The s-t diagram of one node's committed trajectory with the forbidden regions of all moving
/// obstacles and other nodes along its path (seed Abb. 4.13).
/// @throws std::invalid_argument on an unknown node.
std::string st_svg(const Scheduler& scheduler, const std::string& node);

}  // namespace oscar::swarm::tools
