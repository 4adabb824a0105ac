#pragma once
/// @file Node and job specifications and scheduled jobs (seed 002 §4.2.1, §5.2).

#include <string>

#include "oscar/swarm/geometry.hpp"

namespace oscar::swarm {

/// A node of the swarm (seed §5.2 NodeSpecification): a disc robot.
struct NodeSpec {
  std::string id;
  double radius_m = 0;
  double max_speed_mps = 1;
  double x = 0;  ///< initial location
  double y = 0;
  double t = 0;                 ///< initial time (s)
  double turning_radius_m = 0;  ///< > 0: Dubins car, spatial paths planned with OMPL
};

/// A job specification (seed §4.2.1): where (area), when (window) and how long.
struct JobSpec {
  std::string id;
  Polygon area;
  double earliest_start = 0;  ///< t_min
  double latest_finish = 0;   ///< t_max + d (the seed's t_max is the latest start)
  double duration = 0;        ///< d
};

/// A scheduled job: node, location and start time.
struct Job {
  std::string id;
  std::string node;
  double x = 0;
  double y = 0;
  double start = 0;
  double duration = 0;
  JobSpec spec;  ///< what it was scheduled for
  double end() const { return start + duration; }
  Point location() const { return Point(x, y); }
};

}  // namespace oscar::swarm
