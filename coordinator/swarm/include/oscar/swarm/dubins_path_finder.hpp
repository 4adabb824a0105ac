#pragma once
/// @file Spatial paths for nodes with a minimum turning radius, planned with OMPL (Dubins car).

#include <optional>
#include <vector>

#include "oscar/swarm/geometry.hpp"
#include "oscar/swarm/spatial_path_finder.hpp"

namespace oscar::swarm {

/// Plans a curvature-bounded path among inflated static polygons with OMPL's DubinsStateSpace and
/// RRT with shortcutting (seed §2.4/§4.3.1 name a spatial planner per robot kind; issue 6: OMPL for
/// nodes with a minimum turning radius). The start heading points at the goal and the goal heading
/// continues it (nodes stop at jobs, so no heading is carried between legs). The result is the
/// Dubins path sampled every `resolution_m`, each chord checked exactly against the obstacles; a
/// path whose chords cut an obstacle is rejected. Deterministic: every random generator OMPL uses
/// for a leg (RRT's, its state samplers', the path simplifier's) is seeded from Settings::seed and
/// the leg's ends, so a leg plans the same whatever was planned before in the process.
class DubinsPathFinder {
 public:
  struct Settings {
    double turning_radius_m = 1;
    int iterations = 2000;      ///< RRT iterations per attempt
    int restarts = 8;           ///< attempts per query; the shortest path is kept
    double resolution_m = 0.1;  ///< spacing of the returned polyline
    unsigned seed = 1;          ///< with a leg's ends, seeds OMPL's generators for the leg
  };

  /// @throws std::invalid_argument unless the turning radius and resolution are finite and > 0
  /// and iterations and restarts >= 1.
  DubinsPathFinder(std::vector<Polygon> obstacles, Settings settings);

  /// A path from `from` to `to` as a polyline, or nullopt if none was found: also for an end that
  /// is not finite, and if start, goal and obstacles span more than 1e6 turning radii (beyond
  /// what OMPL's Dubins arithmetic is trusted with). Never aborts on OMPL 1.5.2's Dubins
  /// assertions (see SafeDubinsStateSpace in src/).
  std::optional<std::vector<Point>> find(const Point& from, const Point& to) const;

  /// The length of the last path found by OMPL (before sampling), for comparisons.
  double last_length() const { return last_length_; }

 private:
  SpatialPathFinder exact_;  // exact predicates on the same obstacles
  std::vector<Polygon> obstacles_;
  Settings settings_;
  mutable double last_length_ = 0;
};

}  // namespace oscar::swarm
