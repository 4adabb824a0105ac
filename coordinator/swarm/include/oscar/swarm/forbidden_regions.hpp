#pragma once
/// @file Forbidden regions of a moving obstacle in the s–t plane of a path (seed 002 §4.3.3).

#include <utility>
#include <vector>

#include "oscar/swarm/geometry.hpp"
#include "oscar/swarm/moving_obstacle.hpp"

namespace oscar::swarm {

/// The part of the s–t plane a moving obstacle blocks along a path (seed §4.3.3).
struct ForbiddenRegions {
  /// Polygons in (s, t) coordinates (x = arc length, y = time), one per tile piece (Abb. 4.17).
  std::vector<Polygon> regions;
  /// For a path of zero length (the stationary case, eq. 4.16/4.21): blocked time intervals.
  std::vector<std::pair<double, double>> blocked_times;
};

/// Computes the forbidden regions of `obstacle` along `path` for times in [t_lo, t_hi], tile by
/// tile over path segment × obstacle segment, with the regular (eq. 4.17/4.18), parallel
/// (eq. 4.19/4.20) and stationary (eq. 4.21) cases. A path with one point (or only zero-length
/// segments) is stationary and yields blocked_times.
ForbiddenRegions compute_forbidden_regions(const std::vector<Point>& path,
                                           const MovingObstacle& obstacle, double t_lo,
                                           double t_hi);

/// Merges forbidden regions that overlap or share an edge into their union (seed A.7 line 36:
/// forbidden ← forbidden ∪ f), so that the s–t graph sees one boundary instead of the seams of
/// tiles and of neighbouring obstacles: fewer corners (the graph is cubic in them, seed §6.1.2),
/// and no corner or wait edge on a seam that lies inside the union. Regions touching only at a
/// point stay apart. A group whose union would have a hole (a free pocket inside) is kept as it
/// was, since a Polygon has no holes; so is a group whose union fails a soundness check (a piece
/// not covered, or less area than a piece). Near-collinear reflex vertices are dropped, which only
/// grows a region.
std::vector<Polygon> merge_regions(std::vector<Polygon> regions);

/// Which case of seed §4.3.3 (Abb. 4.18) a tile falls into.
enum class TileCase { kRegular, kParallel, kStationary };

/// Classifies a path segment direction `dx` against an obstacle velocity `v` (eq. 4.14–4.16).
TileCase classify_tile(const Point& dx, const Point& v);

}  // namespace oscar::swarm
