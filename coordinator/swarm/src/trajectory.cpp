#include "oscar/swarm/trajectory.hpp"

#include <cmath>
#include <stdexcept>

namespace oscar::swarm {

Trajectory::Trajectory(std::vector<Waypoint> points) {
  for (const auto& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.t)) {
      throw std::invalid_argument("trajectory: waypoint values must be finite");
    }
    if (!points_.empty() && p.t < points_.back().t) {
      throw std::invalid_argument("trajectory: waypoint times must not decrease");
    }
    append(p);
  }
}

Point Trajectory::position_at(double t) const {
  if (points_.empty()) return Point(0, 0);
  if (t <= points_.front().t) return Point(points_.front().x, points_.front().y);
  for (std::size_t i = 1; i < points_.size(); ++i) {
    const auto& a = points_[i - 1];
    const auto& b = points_[i];
    if (t <= b.t) {
      if (b.t <= a.t) return Point(b.x, b.y);
      const double u = (t - a.t) / (b.t - a.t);
      return Point(a.x + u * (b.x - a.x), a.y + u * (b.y - a.y));
    }
  }
  return Point(points_.back().x, points_.back().y);
}

void Trajectory::append(const Waypoint& w) {
  if (!points_.empty()) {
    const auto& l = points_.back();
    if (l.x == w.x && l.y == w.y && l.t == w.t) return;
  }
  points_.push_back(w);
}

void Trajectory::append(const Trajectory& tail) {
  for (const auto& w : tail.points()) append(w);
}

Trajectory Trajectory::spliced(const Trajectory& replacement, double lo, double hi) const {
  Trajectory result;
  for (const auto& p : points_) {
    if (p.t < lo) result.append(p);
  }
  const Point a = replacement.position_at(lo);
  result.append({a.x(), a.y(), lo});
  for (const auto& p : replacement.points()) {
    if (p.t > lo && p.t < hi) result.append(p);
  }
  if (hi < kForever) {
    const Point b = replacement.position_at(hi);
    result.append({b.x(), b.y(), hi});
    for (const auto& p : points_) {
      if (p.t > hi) result.append(p);
    }
  } else if (!replacement.empty() && replacement.end_time() > lo) {
    result.append(replacement.points().back());
  }
  return result;
}

}  // namespace oscar::swarm
