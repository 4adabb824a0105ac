#pragma once
/// @file Exact shortest paths around polygons by a visibility graph (seed 002 §4.3.1).

#include <memory>
#include <optional>
#include <vector>

#include "oscar/swarm/geometry.hpp"

namespace oscar::swarm {

/// Shortest paths among static polygonal obstacles for a point robot (seed §4.3.1, Abb. 4.11/4.12):
/// the graph's vertices are start, goal and the obstacle corners; edges join mutually visible
/// vertices, weighted by Euclidean length; A* (Euclidean distance to the goal, which never
/// overestimates) finds the path. The corner graph is built once; a query adds start and goal,
/// testing the goal's edges only from corners the search reaches. Obstacles are found through an
/// R-tree of their bounding boxes, so a segment is tested exactly only against the polygons near
/// it. The obstacles are already inflated by the node's radius.
class SpatialPathFinder {
 public:
  explicit SpatialPathFinder(std::vector<Polygon> obstacles);

  /// The shortest path from `from` to `to` (both included), or nullopt if one of them lies inside
  /// an obstacle or no path exists.
  std::optional<std::vector<Point>> find(const Point& from, const Point& to) const;

  /// True if the point is free (not in the open interior of any obstacle).
  bool is_free(const Point& p) const;

  /// True if the segment avoids every obstacle's interior.
  bool visible(const Point& a, const Point& b) const;

 private:
  struct Index;  // R-tree of the obstacles' bounding boxes
  template <class F>
  bool any_near(const Point& a, const Point& b, F&& hits) const;

  std::vector<Polygon> obstacles_;
  std::shared_ptr<const Index> index_;
  std::vector<Point> corners_;                                     // corners that are free
  std::vector<std::vector<std::pair<int, double>>> corner_edges_;  // visibility, both directions
};

/// Total length of a polyline.
double path_length(const std::vector<Point>& path);

}  // namespace oscar::swarm
