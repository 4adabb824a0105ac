#include "oscar/swarm/spatial_path_finder.hpp"

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/dijkstra_shortest_paths.hpp>

namespace oscar::swarm {

SpatialPathFinder::SpatialPathFinder(std::vector<Polygon> obstacles)
    : obstacles_(std::move(obstacles)) {
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
      }
    }
  }
}

bool SpatialPathFinder::is_free(const Point& p) const {
  for (const auto& polygon : obstacles_) {
    if (strictly_inside(p, polygon)) return false;
  }
  return true;
}

bool SpatialPathFinder::visible(const Point& a, const Point& b) const {
  for (const auto& polygon : obstacles_) {
    if (segment_hits_interior(a, b, polygon)) return false;
  }
  return true;
}

std::optional<std::vector<Point>> SpatialPathFinder::find(const Point& from,
                                                          const Point& to) const {
  if (!is_free(from) || !is_free(to)) return std::nullopt;
  if (visible(from, to)) return std::vector<Point>{from, to};
  using Graph =
      boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS, boost::no_property,
                            boost::property<boost::edge_weight_t, double>>;
  const int n = static_cast<int>(corners_.size());
  const int start = n;
  const int goal = n + 1;
  Graph graph(n + 2);
  for (int i = 0; i < n; ++i) {
    for (const auto& [j, w] : corner_edges_[i]) boost::add_edge(i, j, w, graph);
    if (visible(from, corners_[i])) boost::add_edge(start, i, distance(from, corners_[i]), graph);
    if (visible(corners_[i], to)) boost::add_edge(i, goal, distance(corners_[i], to), graph);
  }
  std::vector<int> predecessor(n + 2);
  std::vector<double> dist(n + 2);
  boost::dijkstra_shortest_paths(
      graph, start, boost::predecessor_map(predecessor.data()).distance_map(dist.data()));
  if (predecessor[goal] == goal) return std::nullopt;
  std::vector<Point> path;
  for (int v = goal; v != start; v = predecessor[v]) {
    path.push_back(v == goal ? to : corners_[v]);
  }
  path.push_back(from);
  return std::vector<Point>(path.rbegin(), path.rend());
}

double path_length(const std::vector<Point>& path) {
  double s = 0;
  for (std::size_t i = 1; i < path.size(); ++i) s += distance(path[i - 1], path[i]);
  return s;
}

}  // namespace oscar::swarm
