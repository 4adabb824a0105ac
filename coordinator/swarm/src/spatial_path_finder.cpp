#include "oscar/swarm/spatial_path_finder.hpp"

#include <algorithm>
#include <limits>
#include <queue>

#include "boost_geometry.hpp"

namespace oscar::swarm {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using Box = bg::model::box<Point>;

struct SpatialPathFinder::Index {
  bgi::rtree<std::pair<Box, std::size_t>, bgi::rstar<16>> tree;
};

SpatialPathFinder::SpatialPathFinder(std::vector<Polygon> obstacles)
    : obstacles_(std::move(obstacles)) {
  auto index = std::make_shared<Index>();
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    index->tree.insert({bg::return_envelope<Box>(obstacles_[i]), i});
  }
  index_ = std::move(index);
  for (const auto& polygon : obstacles_) {
    for (const auto& c : vertices(polygon)) {
      if (is_free(c)) corners_.push_back(c);
    }
  }
  // The corner-to-corner part of the graph does not depend on start and goal: built once.
  corner_edges_.resize(corners_.size());
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    for (std::size_t j = i + 1; j < corners_.size(); ++j) {
      if (visible(corners_[i], corners_[j])) {
        const double w = distance(corners_[i], corners_[j]);
        corner_edges_[i].emplace_back(static_cast<int>(j), w);
        corner_edges_[j].emplace_back(static_cast<int>(i), w);
      }
    }
  }
}

// True if `hits` holds for an obstacle whose bounding box meets the box of a–b.
template <class F>
bool SpatialPathFinder::any_near(const Point& a, const Point& b, F&& hits) const {
  const Box box(Point(std::min(a.x(), b.x()), std::min(a.y(), b.y())),
                Point(std::max(a.x(), b.x()), std::max(a.y(), b.y())));
  for (auto it = index_->tree.qbegin(bgi::intersects(box)); it != index_->tree.qend(); ++it) {
    if (hits(obstacles_[it->second])) return true;
  }
  return false;
}

bool SpatialPathFinder::is_free(const Point& p) const {
  return !any_near(p, p, [&](const Polygon& o) { return strictly_inside(p, o); });
}

bool SpatialPathFinder::visible(const Point& a, const Point& b) const {
  return !any_near(a, b, [&](const Polygon& o) { return segment_hits_interior(a, b, o); });
}

std::optional<std::vector<Point>> SpatialPathFinder::find(const Point& from,
                                                          const Point& to) const {
  if (!is_free(from) || !is_free(to)) return std::nullopt;
  if (visible(from, to)) return std::vector<Point>{from, to};
  // A* over the corners; vertex n is the start, n + 1 the goal.
  const int n = static_cast<int>(corners_.size());
  const int start = n, goal = n + 1;
  constexpr double kUnreached = std::numeric_limits<double>::infinity();
  std::vector<double> cost(n + 2, kUnreached);
  std::vector<int> previous(n + 2, -1);
  std::vector<bool> done(n + 2, false);
  using Entry = std::pair<double, int>;  // cost + distance to the goal, vertex
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  auto relax = [&](int from_vertex, int v, double c) {
    if (c >= cost[v]) return;
    cost[v] = c;
    previous[v] = from_vertex;
    open.emplace(c + (v == goal ? 0 : distance(corners_[v], to)), v);
  };
  cost[start] = 0;
  for (int i = 0; i < n; ++i) {
    if (visible(from, corners_[i])) relax(start, i, distance(from, corners_[i]));
  }
  while (!open.empty()) {
    const int v = open.top().second;
    open.pop();
    if (done[v]) continue;
    done[v] = true;
    if (v == goal) break;
    for (const auto& [w, d] : corner_edges_[v]) relax(v, w, cost[v] + d);
    if (visible(corners_[v], to)) relax(v, goal, cost[v] + distance(corners_[v], to));
  }
  if (!done[goal]) return std::nullopt;
  std::vector<Point> path;
  for (int v = goal; v != start; v = previous[v]) path.push_back(v == goal ? to : corners_[v]);
  path.push_back(from);
  return std::vector<Point>(path.rbegin(), path.rend());
}

double path_length(const std::vector<Point>& path) {
  double s = 0;
  for (std::size_t i = 1; i < path.size(); ++i) s += distance(path[i - 1], path[i]);
  return s;
}

}  // namespace oscar::swarm
