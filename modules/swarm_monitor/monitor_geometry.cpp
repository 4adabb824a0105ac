#include "monitor_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace oscar::modules::safety {

double signed_area(const Polygon& polygon) {
  double twice = 0;
  const auto n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = polygon[i];
    const auto& b = polygon[(i + 1) % n];
    twice += a.x * b.y - b.x * a.y;
  }
  return twice / 2;
}

bool contains(const Polygon& polygon, Point q) {
  // Count the edges a ray from q towards +x crosses; each edge counts its lower end and not its
  // upper one, so a ray through a vertex counts once.
  bool inside = false;
  const auto n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const auto& a = polygon[i];
    const auto& b = polygon[j];
    if ((a.y > q.y) != (b.y > q.y)) {
      const double x_cross = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
      if (q.x < x_cross) inside = !inside;
    }
  }
  return inside;
}

double distance_to_segment(Point a, Point b, Point q) {
  const double dx = b.x - a.x;
  const double dy = b.y - a.y;
  const double length2 = dx * dx + dy * dy;
  double s = 0;  // where the foot of the perpendicular lies along a-b, clamped to the segment
  if (length2 > 0) s = std::clamp(((q.x - a.x) * dx + (q.y - a.y) * dy) / length2, 0.0, 1.0);
  return std::hypot(q.x - (a.x + s * dx), q.y - (a.y + s * dy));
}

double distance_to_edges(const Polygon& polygon, Point q) {
  double best = std::numeric_limits<double>::infinity();
  const auto n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    best = std::min(best, distance_to_segment(polygon[i], polygon[(i + 1) % n], q));
  }
  return best;
}

double disc_clearance(const Polygon& polygon, Point centre, double radius) {
  const double d = distance_to_edges(polygon, centre);
  return contains(polygon, centre) ? -(d + radius) : d - radius;
}

Polygon translated(const Polygon& polygon, Point offset) {
  Polygon out;
  out.reserve(polygon.size());
  for (const auto& p : polygon) out.push_back({p.x + offset.x, p.y + offset.y});
  return out;
}

Point loop_position(const std::vector<LoopPoint>& loop, double t) {
  if (loop.empty()) return {};
  if (t <= loop.front().t) return {loop.front().x, loop.front().y};
  for (std::size_t i = 1; i < loop.size(); ++i) {
    const auto& a = loop[i - 1];
    const auto& b = loop[i];
    if (t < b.t) {
      const double s = (t - a.t) / (b.t - a.t);  // b.t > t >= a.t: no division by 0
      return {a.x + s * (b.x - a.x), a.y + s * (b.y - a.y)};
    }
  }
  return {loop.back().x, loop.back().y};
}

double loop_phase_s(std::int64_t now_ns, std::int64_t period_ns) {
  const std::int64_t phase = ((now_ns % period_ns) + period_ns) % period_ns;
  return static_cast<double>(phase) * 1e-9;
}

}  // namespace oscar::modules::safety
