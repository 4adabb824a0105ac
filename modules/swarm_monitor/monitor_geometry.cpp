#include "monitor_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace oscar::modules::safety {
namespace {

// Twice the signed area of the triangle a, b, q: positive when q lies left of a->b, 0 when the
// three are collinear. Exact signs matter more here than magnitudes.
double cross(Point a, Point b, Point q) {
  return (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
}

int sign(double v) { return (v > 0) - (v < 0); }

// Whether q, collinear with a and b, lies on the segment between them.
bool within(Point a, Point b, Point q) {
  return std::min(a.x, b.x) <= q.x && q.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= q.y &&
         q.y <= std::max(a.y, b.y);
}

// Whether two edges that share the vertex s meet anywhere else: when their other ends u and v lie
// on the same ray from s (one runs back along the other), or one of them has no length.
bool fold_back(Point s, Point u, Point v) {
  const double dot = (u.x - s.x) * (v.x - s.x) + (u.y - s.y) * (v.y - s.y);
  return cross(s, u, v) == 0 && dot >= 0;
}

}  // namespace

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

bool segments_touch(Point a, Point b, Point c, Point d) {
  const int a_side = sign(cross(c, d, a));
  const int b_side = sign(cross(c, d, b));
  const int c_side = sign(cross(a, b, c));
  const int d_side = sign(cross(a, b, d));
  if (a_side * b_side < 0 && c_side * d_side < 0) return true;  // a proper crossing
  // Otherwise they meet only where an end of one lies on the other.
  return (a_side == 0 && within(c, d, a)) || (b_side == 0 && within(c, d, b)) ||
         (c_side == 0 && within(a, b, c)) || (d_side == 0 && within(a, b, d));
}

std::optional<std::pair<std::size_t, std::size_t>> self_contact(const Polygon& polygon) {
  const auto n = polygon.size();
  auto vertex = [&](std::size_t i) { return polygon[i % n]; };
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      bool meet = false;
      if (j == i + 1) {  // edge j starts where edge i ends
        meet = fold_back(vertex(j), vertex(i), vertex(j + 1));
      } else if (i == 0 && j == n - 1) {  // edge i starts where edge j ends
        meet = fold_back(vertex(0), vertex(1), vertex(j));
      } else {
        meet = segments_touch(vertex(i), vertex(i + 1), vertex(j), vertex(j + 1));
      }
      if (meet) return std::pair{i, j};
    }
  }
  return std::nullopt;
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
