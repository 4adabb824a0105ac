#pragma once
/// @file Path-velocity decomposition for one node (seed 002 §4.3).

#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "oscar/swarm/moving_obstacle.hpp"
#include "oscar/swarm/spatial_path_finder.hpp"
#include "oscar/swarm/trajectory.hpp"
#include "oscar/swarm/velocity_planner.hpp"

namespace oscar::swarm {

/// Plans collision-free trajectories for one node by path-velocity decomposition (seed §4.3):
/// spatial path around static obstacles, then a velocity profile around the forbidden regions of
/// all moving obstacles (already inflated by the node's radius), composed as in Abb. 4.15.
class TrajectoryPlanner {
 public:
  /// The spatial planner: the exact visibility graph or OMPL's Dubins planner (per node).
  using PathFunction = std::function<std::optional<std::vector<Point>>(const Point&, const Point&)>;

  TrajectoryPlanner(PathFunction path, std::vector<MovingObstacle> obstacles,
                    VelocityPlanner::Settings settings);

  /// Shortest spatial path, or nullopt.
  std::optional<std::vector<Point>> path(const Point& from, const Point& to) const;

  /// The earliest arrival time along `path` leaving at t0, no later than t_latest (A.6).
  std::optional<double> earliest_arrival(const std::vector<Point>& path, double t0,
                                         double t_latest) const;

  /// A trajectory along `path` leaving at t0 and arriving exactly at t1 (A.5, with waits).
  std::optional<Trajectory> fixed_arrival(const std::vector<Point>& path, double t0,
                                          double t1) const;

  /// Times in [lo, hi] when a node standing at p would be hit (stationary case, eq. 4.21).
  std::vector<std::pair<double, double>> blocked_times(const Point& p, double lo, double hi) const;

  /// The first time in [lo, hi] at which `trajectory` runs into a moving obstacle (its s–t
  /// profile enters a forbidden region of its own path), or none: a trajectory planned before
  /// the obstacles changed, checked against them.
  std::optional<double> first_hit(const Trajectory& trajectory, double lo, double hi) const;

 private:
  std::vector<Polygon> regions(const std::vector<Point>& path, double lo, double hi) const;

  PathFunction path_;
  std::vector<MovingObstacle> obstacles_;
  VelocityPlanner::Settings settings_;
};

/// Composes a trajectory from a spatial path and an s–t profile (Abb. 4.15).
Trajectory compose(const std::vector<Point>& path, const std::vector<Point>& profile);

}  // namespace oscar::swarm
