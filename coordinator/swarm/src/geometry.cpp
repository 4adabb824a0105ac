#include "oscar/swarm/geometry.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <boost/geometry.hpp>
#include <cmath>
#include <stdexcept>

namespace oscar::swarm {

namespace bg = boost::geometry;

double distance(const Point& a, const Point& b) { return std::hypot(a.x() - b.x(), a.y() - b.y()); }

const std::vector<Point>& vertices(const Polygon& polygon) { return polygon.outer(); }

namespace {

constexpr const char* kSelfIntersecting =
    "polygon is self-intersecting (two of its edges cross or touch); it must be simple";
constexpr const char* kZeroArea = "polygon has zero area";

// The rule a polygon breaks, by Boost.Geometry's failure type (is_valid after bg::correct).
std::string polygon_fault(const Polygon& polygon, bg::validity_failure_type failure) {
  switch (failure) {
    case bg::failure_wrong_topological_dimension:  // one or two distinct points
      return "a polygon needs at least 3 distinct vertices";
    case bg::failure_spikes:  // all vertices on one line count as spikes too
      return std::abs(bg::area(polygon)) <= kEpsilon
                 ? kZeroArea
                 : "polygon has a spike (an edge runs back along the one before it)";
    case bg::failure_self_intersections:
      return kSelfIntersecting;
    case bg::failure_wrong_orientation:
      // bg::correct orients by the signed area: it is still wrong when the loops of a
      // self-intersecting ring cancel out (a symmetric bow-tie).
      return bg::intersects(polygon) ? kSelfIntersecting : kZeroArea;
    default: {
      std::string reason;
      bg::is_valid(polygon, reason);
      return "polygon is not valid: " + reason;
    }
  }
}

}  // namespace

Polygon make_polygon(const std::vector<Point>& points, const std::string& what) {
  if (points.size() < 3) {
    throw std::invalid_argument(
        fmt::format("{}: a polygon needs at least 3 vertices, got {}", what, points.size()));
  }
  for (const auto& p : points) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) {
      throw std::invalid_argument(fmt::format("{}: polygon coordinates must be finite", what));
    }
  }
  Polygon polygon;
  polygon.outer().assign(points.begin(), points.end());
  bg::correct(polygon);
  bg::validity_failure_type failure{};
  if (!bg::is_valid(polygon, failure)) {
    throw std::invalid_argument(fmt::format("{}: {}", what, polygon_fault(polygon, failure)));
  }
  if (std::abs(bg::area(polygon)) <= kEpsilon) {
    throw std::invalid_argument(fmt::format("{}: {}", what, kZeroArea));
  }
  return polygon;
}

double point_segment_distance(const Point& p, const Point& a, const Point& b) {
  const double dx = b.x() - a.x();
  const double dy = b.y() - a.y();
  const double len2 = dx * dx + dy * dy;
  double u = len2 > 0 ? ((p.x() - a.x()) * dx + (p.y() - a.y()) * dy) / len2 : 0.0;
  u = std::clamp(u, 0.0, 1.0);
  return std::hypot(p.x() - (a.x() + u * dx), p.y() - (a.y() + u * dy));
}

namespace {

// point_segment_distance(p, a, b) <= eps without a square root: this test runs for every edge of
// every region in the s–t graph's visibility checks, where std::hypot was a third of the time.
bool within(const Point& p, const Point& a, const Point& b, double eps) {
  const double dx = b.x() - a.x();
  const double dy = b.y() - a.y();
  const double len2 = dx * dx + dy * dy;
  double u = len2 > 0 ? ((p.x() - a.x()) * dx + (p.y() - a.y()) * dy) / len2 : 0.0;
  u = std::clamp(u, 0.0, 1.0);
  const double ex = p.x() - (a.x() + u * dx);
  const double ey = p.y() - (a.y() + u * dy);
  return ex * ex + ey * ey <= eps * eps;
}

}  // namespace

bool strictly_inside(const Point& p, const Polygon& polygon) {
  const auto& v = vertices(polygon);
  bool inside = false;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    if (within(p, v[j], v[i], kEpsilon)) return false;
    if ((v[i].y() > p.y()) != (v[j].y() > p.y())) {
      const double x =
          v[j].x() + (p.y() - v[j].y()) * (v[i].x() - v[j].x()) / (v[i].y() - v[j].y());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
}

std::vector<double> line_crossings(const Point& p, const Point& d, const Polygon& polygon) {
  std::vector<double> result;
  const auto& v = vertices(polygon);
  const double dd = d.x() * d.x() + d.y() * d.y();
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    const Point& c = v[j];
    const double ex = v[i].x() - c.x();
    const double ey = v[i].y() - c.y();
    const double den = d.x() * ey - d.y() * ex;
    const double wx = c.x() - p.x();
    const double wy = c.y() - p.y();
    // |den| <= 1e-15 |d| |e|, squared (no square roots per edge).
    if (den * den <= 1e-30 * dd * (ex * ex + ey * ey) + 1e-300) {
      // Parallel: if collinear, both edge ends count as crossings.
      const double cross = wx * d.y() - wy * d.x();
      if (dd > 0 && cross * cross <= kEpsilon * kEpsilon * dd) {
        result.push_back((wx * d.x() + wy * d.y()) / dd);
        result.push_back(((v[i].x() - p.x()) * d.x() + (v[i].y() - p.y()) * d.y()) / dd);
      }
      continue;
    }
    const double u = (wx * ey - wy * ex) / den;
    const double w = (wx * d.y() - wy * d.x()) / den;
    if (w >= -1e-12 && w <= 1 + 1e-12) result.push_back(u);
  }
  std::sort(result.begin(), result.end());
  return result;
}

std::vector<std::pair<double, double>> line_inside_intervals(const Point& p, const Point& d,
                                                             const Polygon& polygon) {
  std::vector<std::pair<double, double>> result;
  const auto u = line_crossings(p, d, polygon);
  for (std::size_t k = 0; k + 1 < u.size(); ++k) {
    if (u[k + 1] - u[k] <= 1e-12) continue;
    const double m = 0.5 * (u[k] + u[k + 1]);
    if (strictly_inside(Point(p.x() + m * d.x(), p.y() + m * d.y()), polygon)) {
      if (!result.empty() && std::abs(result.back().second - u[k]) <= 1e-12) {
        result.back().second = u[k + 1];
      } else {
        result.emplace_back(u[k], u[k + 1]);
      }
    }
  }
  return result;
}

bool segment_hits_interior(const Point& a, const Point& b, const Polygon& polygon) {
  const Point d(b.x() - a.x(), b.y() - a.y());
  if (d.x() == 0 && d.y() == 0) return strictly_inside(a, polygon);
  // Cheap rejection by bounding boxes.
  const auto box = bg::return_envelope<bg::model::box<Point>>(polygon);
  if (std::max(a.x(), b.x()) < box.min_corner().x() ||
      std::min(a.x(), b.x()) > box.max_corner().x() ||
      std::max(a.y(), b.y()) < box.min_corner().y() ||
      std::min(a.y(), b.y()) > box.max_corner().y()) {
    return false;
  }
  std::vector<double> u{0.0, 1.0};
  for (double c : line_crossings(a, d, polygon)) {
    if (c > 0 && c < 1) u.push_back(c);
  }
  std::sort(u.begin(), u.end());
  for (std::size_t k = 0; k + 1 < u.size(); ++k) {
    if (u[k + 1] - u[k] <= 1e-12) continue;
    const double m = 0.5 * (u[k] + u[k + 1]);
    if (strictly_inside(Point(a.x() + m * d.x(), a.y() + m * d.y()), polygon)) return true;
  }
  return false;
}

Polygon inflate(const Polygon& polygon, double distance_m) {
  if (distance_m <= 0) return polygon;
  using Closed = bg::model::polygon<Point, false, true>;
  Closed closed;
  closed.outer().assign(polygon.outer().begin(), polygon.outer().end());
  bg::correct(closed);
  bg::model::multi_polygon<Closed> grown;
  bg::buffer(closed, grown, bg::strategy::buffer::distance_symmetric<double>(distance_m),
             bg::strategy::buffer::side_straight(), bg::strategy::buffer::join_miter(5.0),
             bg::strategy::buffer::end_flat(), bg::strategy::buffer::point_square());
  Polygon result;
  if (grown.empty()) return result;
  const auto& ring = grown.front().outer();
  result.outer().assign(ring.begin(), ring.end() - 1);
  bg::correct(result);
  return result;
}

Polygon disc_polygon(double radius_m) {
  constexpr int kSides = 8;
  const double r = radius_m / std::cos(M_PI / kSides) * (1 + 1e-9);
  Polygon result;
  for (int k = 0; k < kSides; ++k) {
    const double a = 2 * M_PI * (k + 0.5) / kSides;
    result.outer().emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return result;
}

Polygon translate(const Polygon& polygon, double dx, double dy) {
  Polygon result;
  for (const auto& p : polygon.outer()) result.outer().emplace_back(p.x() + dx, p.y() + dy);
  return result;
}

}  // namespace oscar::swarm
