#pragma once
/// @file Piecewise-linear trajectories in x × y × t (seed 002 §4.3, Abb. 4.15).

#include <limits>
#include <vector>

#include "oscar/swarm/geometry.hpp"

namespace oscar::swarm {

/// One vertex of a trajectory: a place and the time the node is there.
struct Waypoint {
  double x = 0;
  double y = 0;
  double t = 0;
};

/// Times beyond the last waypoint: a node stays at its last waypoint until kForever.
inline constexpr double kForever = 4e6;

/// A piecewise-linear trajectory with non-decreasing times. Before the first waypoint it is
/// undefined; after the last one the node stays at the last waypoint (seed §4.2.1: a node idles at
/// its last job).
class Trajectory {
 public:
  Trajectory() = default;
  /// @throws std::invalid_argument if the times decrease or a value is not finite.
  explicit Trajectory(std::vector<Waypoint> points);

  /// The waypoints.
  const std::vector<Waypoint>& points() const { return points_; }
  bool empty() const { return points_.empty(); }
  double start_time() const { return points_.front().t; }
  double end_time() const { return points_.back().t; }

  /// Position at time t (clamped to the first/last waypoint outside the time span).
  Point position_at(double t) const;

  /// This trajectory before `lo` and after `hi`, `replacement` in [lo, hi].
  Trajectory spliced(const Trajectory& replacement, double lo, double hi) const;

  /// Appends a waypoint; drops it if it repeats the last one.
  void append(const Waypoint& w);

  /// Appends all waypoints of `tail` (the first may repeat the current last waypoint).
  void append(const Trajectory& tail);

 private:
  std::vector<Waypoint> points_;
};

}  // namespace oscar::swarm
