#include "pilot_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace oscar::modules {
namespace {
constexpr double kStill = 1e-9;  // m: a segment shorter than this does not move the robot

double length(const TimedPoint& a, const TimedPoint& b) { return std::hypot(b.x - a.x, b.y - a.y); }

void add(std::vector<TimedPoint>& points, const TimedPoint& p) {
  if (points.empty() || !(points.back() == p)) points.push_back(p);
}
}  // namespace

Place place_at(const std::vector<TimedPoint>& points, Stamp t) {
  // The first point at or after t (the swarm planner's Trajectory::position_at).
  const auto it = std::lower_bound(points.begin(), points.end(), t,
                                   [](const TimedPoint& p, Stamp v) { return p.t < v; });
  if (it == points.begin()) return {points.front().x, points.front().y};
  if (it == points.end()) return {points.back().x, points.back().y};
  const auto& a = *(it - 1);
  const auto& b = *it;
  if (b.t <= a.t) return {b.x, b.y};
  const double u = static_cast<double>(t - a.t) / static_cast<double>(b.t - a.t);
  return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y)};
}

PilotTrajectory::PilotTrajectory(double x, double y, double heading)
    : points_{{x, y, 0}}, base_heading_(std::remainder(heading, 2 * M_PI)) {}

double PilotTrajectory::heading_before(std::size_t segment_end) const {
  for (std::size_t j = std::min(segment_end, points_.size() - 1); j-- > 0;) {
    const auto& a = points_[j];
    const auto& b = points_[j + 1];
    if (length(a, b) > kStill) return std::atan2(b.y - a.y, b.x - a.x);
  }
  return base_heading_;
}

Motion PilotTrajectory::at(Stamp t) const {
  const Place p = place_at(points_, t);
  Motion m{p.x, p.y, base_heading_, 0};
  // The segment the robot is in: the last point at or before t and the next one.
  const auto after = std::upper_bound(points_.begin(), points_.end(), t,
                                      [](Stamp v, const TimedPoint& q) { return v < q.t; });
  if (after == points_.begin()) return m;  // before the trajectory: standing at its start
  const auto k = static_cast<std::size_t>(after - points_.begin()) - 1;
  m.heading = heading_before(k + 1);  // this segment if it moves, else the last one that moved
  if (k + 1 < points_.size()) {
    const auto& a = points_[k];
    const auto& b = points_[k + 1];
    const double d = length(a, b);
    if (d > kStill) m.speed = d / (static_cast<double>(b.t - a.t) * 1e-9);
  }
  return m;
}

std::uint64_t PilotTrajectory::transaction_at(Stamp t) const {
  for (const auto& s : spans_) {
    if (s.lo <= t && t <= s.hi) return s.transaction;
  }
  return 0;
}

void PilotTrajectory::splice(const std::vector<TimedPoint>& points, Stamp lo, Stamp hi,
                             bool open_end, std::uint64_t transaction) {
  std::vector<TimedPoint> result;
  for (const auto& p : points_) {
    if (p.t < lo) add(result, p);
  }
  const Place start = place_at(points, lo);
  add(result, {start.x, start.y, lo});
  for (const auto& p : points) {
    if (p.t > lo && (open_end || p.t < hi)) add(result, p);
  }
  if (!open_end) {
    const Place end = place_at(points, hi);
    add(result, {end.x, end.y, hi});
    for (const auto& p : points_) {
      if (p.t > hi) add(result, p);
    }
  }
  // The heading before the first point stays; a splice before it keeps it too.
  points_ = std::move(result);

  // The sections of other transactions lose what this one covers.
  const Stamp cut_hi = open_end ? std::numeric_limits<Stamp>::max() : hi;
  std::vector<Span> spans;
  for (const auto& s : spans_) {
    if (s.hi < lo || s.lo > cut_hi) {
      spans.push_back(s);
      continue;
    }
    if (s.lo < lo) spans.push_back({s.lo, lo - 1, s.transaction});
    if (s.hi > cut_hi) spans.push_back({cut_hi + 1, s.hi, s.transaction});
  }
  spans.push_back({lo, open_end ? std::max(lo, points.back().t) : hi, transaction});
  spans_ = std::move(spans);
}

std::vector<TimedPoint> PilotTrajectory::from(Stamp t) const {
  const Place p = place_at(points_, t);
  std::vector<TimedPoint> result{{p.x, p.y, t}};
  for (const auto& q : points_) {
    if (q.t > t) add(result, q);
  }
  return result;
}

void PilotTrajectory::forget_before(Stamp t) {
  const auto after = std::upper_bound(points_.begin(), points_.end(), t,
                                      [](Stamp v, const TimedPoint& q) { return v < q.t; });
  if (after != points_.begin()) {
    const auto k = static_cast<std::size_t>(after - points_.begin()) - 1;  // last point <= t
    if (k > 0) {
      base_heading_ = heading_before(k);
      points_.erase(points_.begin(), points_.begin() + static_cast<std::ptrdiff_t>(k));
    }
  }
  std::erase_if(spans_, [&](const Span& s) { return s.hi < t; });
}

void PilotTrajectory::stop_at(Stamp t) {
  const Motion m = at(t);
  points_ = {{m.x, m.y, t}};
  base_heading_ = m.heading;
  spans_.clear();
}

}  // namespace oscar::modules
