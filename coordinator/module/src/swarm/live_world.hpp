#pragma once
// The running swarm's world (docs/swarm.md, "A world that changes"): named obstacles as the
// system file and requests give them, in Unix time, as the wire carries them (SwarmObstacle).
// The planner gets a World made of it for a span of time, loops unrolled over that span.

#include <string>
#include <vector>

#include <oscar/swarm.h>

#include "swarm_wire.hpp"

namespace oscar::coordinator {

class LiveWorld {
 public:
  /// How far ahead loops are unrolled for the planner; the service unrolls them again before
  /// the present gets near the end.
  static constexpr double kLoopSpan = 120;  // s

  /// Adds an obstacle.
  /// @throws std::invalid_argument naming the obstacle and the rule: a name empty, too long or
  /// in use; a shape that is no simple polygon; a path whose times go back, a loop that does not
  /// start at 0, end at loop_ns or end where it starts; a moving path of fewer than 2 points.
  void add(SwarmObstacle obstacle);
  /// @throws std::invalid_argument on a name of no obstacle.
  void remove(const std::string& name);

  const std::vector<SwarmObstacle>& obstacles() const { return obstacles_; }
  bool has_loops() const;
  /// The planner's world over [from, to] (planner seconds): loops unrolled over that span, a
  /// finite path as it is.
  swarm::World planned(const swarm_wire::Clock& clock, double from, double to) const;
  /// What a safety monitor is told (command `world`).
  SwarmWorld wire() const;

 private:
  std::vector<SwarmObstacle> obstacles_;
};

/// The obstacle's shape as the planner's polygon.
/// @throws std::invalid_argument naming the obstacle: x and y of different lengths, no simple
/// polygon.
swarm::Polygon obstacle_shape(const SwarmObstacle& obstacle);

}  // namespace oscar::coordinator
