#include "oscar/swarm/trajectory_planner.hpp"

#include <algorithm>
#include <boost/geometry.hpp>
#include <cmath>

#include "oscar/swarm/forbidden_regions.hpp"

namespace oscar::swarm {

namespace bg = boost::geometry;

namespace {

struct Box {
  double x0, y0, x1, y1;
  bool overlaps(const Box& o) const { return x0 <= o.x1 && o.x0 <= x1 && y0 <= o.y1 && o.y0 <= y1; }
};

// The area an obstacle sweeps during [lo, hi]: cheap rejection before the exact tiles.
Box swept_box(const MovingObstacle& o, double lo, double hi) {
  const auto shape = bg::return_envelope<bg::model::box<Point>>(o.shape);
  Box b{1e300, 1e300, -1e300, -1e300};
  auto add = [&](const Point& p) {
    b.x0 = std::min(b.x0, p.x() + shape.min_corner().x());
    b.y0 = std::min(b.y0, p.y() + shape.min_corner().y());
    b.x1 = std::max(b.x1, p.x() + shape.max_corner().x());
    b.y1 = std::max(b.y1, p.y() + shape.max_corner().y());
  };
  const auto& pts = o.trajectory.points();
  if (pts.empty() || pts.back().t < lo || pts.front().t > hi) return b;
  add(o.trajectory.position_at(std::max(lo, pts.front().t)));
  add(o.trajectory.position_at(std::min(hi, pts.back().t)));
  for (const auto& p : pts) {
    if (p.t > lo && p.t < hi) add(Point(p.x, p.y));
  }
  return b;
}

Box path_box(const std::vector<Point>& path) {
  Box b{1e300, 1e300, -1e300, -1e300};
  for (const auto& p : path) {
    b.x0 = std::min(b.x0, p.x());
    b.y0 = std::min(b.y0, p.y());
    b.x1 = std::max(b.x1, p.x());
    b.y1 = std::max(b.y1, p.y());
  }
  return b;
}

}  // namespace

TrajectoryPlanner::TrajectoryPlanner(PathFunction path, std::vector<MovingObstacle> obstacles,
                                     VelocityPlanner::Settings settings)
    : path_(std::move(path)), obstacles_(std::move(obstacles)), settings_(settings) {}

std::optional<std::vector<Point>> TrajectoryPlanner::path(const Point& from,
                                                          const Point& to) const {
  return path_(from, to);
}

std::vector<Polygon> TrajectoryPlanner::regions(const std::vector<Point>& path, double lo,
                                                double hi) const {
  std::vector<Polygon> result;
  const Box pb = path_box(path);
  for (const auto& o : obstacles_) {
    if (!swept_box(o, lo, hi).overlaps(pb)) continue;
    auto r = compute_forbidden_regions(path, o, lo, hi);
    for (auto& p : r.regions) result.push_back(std::move(p));
  }
  return result;
}

std::vector<std::pair<double, double>> TrajectoryPlanner::blocked_times(const Point& p, double lo,
                                                                        double hi) const {
  std::vector<std::pair<double, double>> result;
  const std::vector<Point> path{p};
  const Box pb = path_box(path);
  for (const auto& o : obstacles_) {
    if (!swept_box(o, lo, hi).overlaps(pb)) continue;
    for (const auto& b : compute_forbidden_regions(path, o, lo, hi).blocked_times) {
      result.push_back(b);
    }
  }
  std::sort(result.begin(), result.end());
  return result;
}

namespace {
bool overlaps_open(const std::vector<std::pair<double, double>>& blocked, double a, double b) {
  for (const auto& [lo, hi] : blocked) {
    if (lo < b && a < hi && std::min(hi, b) - std::max(lo, a) > kEpsilon) return true;
  }
  return false;
}
}  // namespace

std::optional<double> TrajectoryPlanner::earliest_arrival(const std::vector<Point>& path, double t0,
                                                          double t_latest) const {
  const double length = path_length(path);
  if (length <= kEpsilon) return t0;
  const double t_hi = t_latest + 1;  // regions a little past t_latest keep the goal test exact
  VelocityPlanner planner(length, t0, regions(path, t0, t_hi), settings_);
  auto profile = planner.earliest_arrival(t_latest);
  if (!profile) return std::nullopt;
  return profile->back().y();
}

std::optional<Trajectory> TrajectoryPlanner::fixed_arrival(const std::vector<Point>& path,
                                                           double t0, double t1) const {
  const double length = path_length(path);
  if (length <= kEpsilon) {
    if (overlaps_open(blocked_times(path.front(), t0, t1), t0, t1)) return std::nullopt;
    Trajectory t;
    t.append({path.front().x(), path.front().y(), t0});
    t.append({path.front().x(), path.front().y(), t1});
    return t;
  }
  VelocityPlanner planner(length, t0, regions(path, t0, t1), settings_);
  auto profile = planner.fixed_arrival(t1);
  if (!profile) return std::nullopt;
  return compose(path, *profile);
}

std::optional<double> TrajectoryPlanner::first_hit(const Trajectory& trajectory, double lo,
                                                   double hi) const {
  // The trajectory over [lo, hi] as a spatial path and its s–t profile (s never decreases).
  std::vector<Waypoint> w{{trajectory.position_at(lo).x(), trajectory.position_at(lo).y(), lo}};
  for (const auto& p : trajectory.points()) {
    if (p.t > lo && p.t < hi) w.push_back(p);
  }
  const Point end = trajectory.position_at(hi);
  w.push_back({end.x(), end.y(), hi});
  std::vector<Point> path{Point(w.front().x, w.front().y)};
  std::vector<Point> profile{Point(0, lo)};
  double s = 0;
  for (std::size_t k = 1; k < w.size(); ++k) {
    const Point p(w[k].x, w[k].y);
    const double d = distance(path.back(), p);
    if (d > kEpsilon) {
      path.push_back(p);
      s += d;
    }
    profile.emplace_back(s, w[k].t);
  }
  if (path.size() == 1) {  // it stands still all the while
    for (const auto& [from, to] : blocked_times(path.front(), lo, hi)) {
      if (to - from > kEpsilon) return from;
    }
    return std::nullopt;
  }
  const VelocityPlanner st(s, lo, regions(path, lo, hi), settings_);
  for (std::size_t k = 1; k < profile.size(); ++k) {
    if (!st.free(profile[k - 1], profile[k])) return profile[k - 1].y();
  }
  return std::nullopt;
}

Trajectory compose(const std::vector<Point>& path, const std::vector<Point>& profile) {
  std::vector<double> s(path.size(), 0.0);
  for (std::size_t i = 1; i < path.size(); ++i) s[i] = s[i - 1] + distance(path[i - 1], path[i]);
  auto at = [&](double arc) {
    for (std::size_t i = 1; i < path.size(); ++i) {
      if (arc <= s[i] || i + 1 == path.size()) {
        const double len = s[i] - s[i - 1];
        const double u = len > 0 ? std::clamp((arc - s[i - 1]) / len, 0.0, 1.0) : 0.0;
        return Point(path[i - 1].x() + u * (path[i].x() - path[i - 1].x()),
                     path[i - 1].y() + u * (path[i].y() - path[i - 1].y()));
      }
    }
    return path.front();
  };
  Trajectory result;
  const Point p0 = at(profile.front().x());
  result.append({p0.x(), p0.y(), profile.front().y()});
  for (std::size_t k = 1; k < profile.size(); ++k) {
    const Point& a = profile[k - 1];
    const Point& b = profile[k];
    if (b.x() - a.x() > kEpsilon) {
      for (std::size_t i = 1; i + 1 < path.size(); ++i) {
        if (s[i] > a.x() && s[i] < b.x()) {
          const double t = a.y() + (s[i] - a.x()) / (b.x() - a.x()) * (b.y() - a.y());
          result.append({path[i].x(), path[i].y(), t});
        }
      }
    }
    // The last profile vertex is the path's end exactly (no rounding through arc length).
    const Point p = k + 1 == profile.size() ? path.back() : at(b.x());
    result.append({p.x(), p.y(), b.y()});
  }
  return result;
}

}  // namespace oscar::swarm
