#include "oscar/swarm/velocity_planner.hpp"

#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/dijkstra_shortest_paths.hpp>
#include <cmath>
#include <limits>

#include "oscar/swarm/forbidden_regions.hpp"

namespace oscar::swarm {

namespace {

// A difference of two times carries the rounding of the larger one: at t = 1e6 s a double resolves
// about 1.2e-10 s (seed §5.3.1). A full-speed edge computed as t_a + Δs / v must still pass
// eq. 4.13 there, so the speed test allows a few units in the last place of the times involved.
double time_slack(double t_a, double t_b) {
  return 4 * std::numeric_limits<double>::epsilon() * std::max({1.0, std::abs(t_a), std::abs(t_b)});
}

}  // namespace

VelocityPlanner::VelocityPlanner(double s_final, double t_start, std::vector<Polygon> regions,
                                 Settings settings)
    : s_final_(s_final),
      t_start_(t_start),
      regions_(merge_regions(std::move(regions))),
      settings_(settings) {
  if (settings_.v_leave <= 0) settings_.v_leave = settings_.v_max;
  for (const auto& r : regions_) {
    Bounds b{1e300, 1e300, -1e300, -1e300};
    for (const auto& v : vertices(r)) {
      b = {std::min(b.s0, v.x()), std::min(b.t0, v.y()), std::max(b.s1, v.x()),
           std::max(b.t1, v.y())};
    }
    bounds_.push_back(b);
  }
}

bool VelocityPlanner::free(const Point& a, const Point& b) const {
  const double s0 = std::min(a.x(), b.x()), s1 = std::max(a.x(), b.x());
  const double t0 = std::min(a.y(), b.y()), t1 = std::max(a.y(), b.y());
  for (std::size_t i = 0; i < regions_.size(); ++i) {
    const Bounds& r = bounds_[i];
    if (s1 < r.s0 || s0 > r.s1 || t1 < r.t0 || t0 > r.t1) continue;
    if (segment_hits_interior(a, b, regions_[i])) return false;
  }
  return true;
}

bool VelocityPlanner::edge_ok(const Point& a, const Point& b) const {
  const double ds = b.x() - a.x();
  const double dt = b.y() - a.y();
  if (dt <= 0 || ds < -kEpsilon) return false;  // eq. 4.12, forward only
  if (ds > settings_.v_max * (dt + time_slack(a.y(), b.y())) + 1e-12) return false;  // eq. 4.13
  return free(a, b);
}

bool VelocityPlanner::inside_any(const Point& p) const {
  for (std::size_t i = 0; i < regions_.size(); ++i) {
    const Bounds& r = bounds_[i];
    if (p.x() <= r.s0 || p.x() >= r.s1 || p.y() <= r.t0 || p.y() >= r.t1) continue;
    if (strictly_inside(p, regions_[i])) return true;
  }
  return false;
}

std::vector<Point> VelocityPlanner::corners(double t_max) const {
  std::vector<Point> result;
  for (const auto& r : regions_) {
    for (const auto& c : vertices(r)) {
      if (c.y() < t_start_ || c.y() > t_max || c.x() < -kEpsilon || c.x() > s_final_ + kEpsilon) {
        continue;
      }
      if (!inside_any(c)) result.push_back(c);
    }
  }
  return result;
}

std::optional<std::vector<Point>> VelocityPlanner::fixed_arrival(double t_final) const {
  const Point start(0, t_start_);
  const Point goal(s_final_, t_final);
  if (t_final < t_start_ ||
      s_final_ > settings_.v_max * (t_final - t_start_ + time_slack(t_start_, t_final)) + 1e-12) {
    return std::nullopt;
  }
  std::vector<Point> nodes{start, goal};
  for (const auto& c : corners(t_final)) nodes.push_back(c);
  if (inside_any(start) || inside_any(goal)) return std::nullopt;
  if (s_final_ <= kEpsilon) {
    // Stationary: only a wait is possible.
    if (t_final <= t_start_ || free(start, goal)) return std::vector<Point>{start, goal};
    return std::nullopt;
  }
  using Graph =
      boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS, boost::no_property,
                            boost::property<boost::edge_weight_t, double>>;
  const std::size_t base = nodes.size();
  Graph graph(base);
  auto cost = [](const Point& a, const Point& b) {
    return b.x() - a.x() > kEpsilon ? b.y() - a.y() : 0.0;  // driving time; waiting is free
  };
  for (std::size_t i = 0; i < base; ++i) {
    for (std::size_t j = 0; j < base; ++j) {
      if (i == j) continue;
      const Point a = nodes[i];  // copies: nodes grows below
      const Point b = nodes[j];
      if (edge_ok(a, b)) boost::add_edge(i, j, cost(a, b) + 1e-9, graph);
      // §4.3.4: wait at s_a, then leave with v_L to reach b exactly.
      if (b.x() - a.x() > kEpsilon) {
        const Point w(a.x(), b.y() - (b.x() - a.x()) / settings_.v_leave);
        if (w.y() - a.y() >= std::max(settings_.wait_threshold_s, kEpsilon) && edge_ok(a, w) &&
            edge_ok(w, b)) {
          const auto k = boost::add_vertex(graph);
          nodes.push_back(w);
          boost::add_edge(i, k, 1e-9, graph);
          boost::add_edge(k, j, cost(w, b) + 1e-9, graph);
        }
      }
    }
  }
  const std::size_t n = boost::num_vertices(graph);
  std::vector<std::size_t> predecessor(n);
  std::vector<double> dist(n);
  boost::dijkstra_shortest_paths(
      graph, 0, boost::predecessor_map(predecessor.data()).distance_map(dist.data()));
  if (predecessor[1] == 1) return std::nullopt;
  std::vector<Point> path;
  for (std::size_t v = 1; v != 0; v = predecessor[v]) path.push_back(nodes[v]);
  path.push_back(start);
  std::reverse(path.begin(), path.end());
  return path;
}

std::optional<std::vector<Point>> VelocityPlanner::earliest_arrival(double t_latest) const {
  const Point start(0, t_start_);
  if (inside_any(start)) return std::nullopt;
  std::vector<Point> nodes{start};
  for (const auto& c : corners(t_latest)) nodes.push_back(c);
  std::sort(nodes.begin() + 1, nodes.end(),
            [](const Point& a, const Point& b) { return a.y() < b.y(); });
  std::vector<char> reached(nodes.size(), 0);
  reached[0] = 1;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (!reached[i]) continue;
    const Point& a = nodes[i];
    // Max-speed edge to the line s = s_final (Abb. 4.14b).
    const double t_goal = a.y() + (s_final_ - a.x()) / settings_.v_max;
    if (t_goal < best && t_goal <= t_latest + 1e-12) {
      const Point g(s_final_, std::max(t_goal, a.y()));
      if (!inside_any(g) && (g.y() > a.y() ? free(a, g) : true)) best = g.y();
    }
    for (std::size_t j = i + 1; j < nodes.size(); ++j) {
      if (!reached[j] && edge_ok(a, nodes[j])) reached[j] = 1;
    }
  }
  if (!std::isfinite(best)) return std::nullopt;
  return fixed_arrival(std::max(best, t_start_));
}

}  // namespace oscar::swarm
