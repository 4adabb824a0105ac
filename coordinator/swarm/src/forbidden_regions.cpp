#include "oscar/swarm/forbidden_regions.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "boost_geometry.hpp"

namespace oscar::swarm {

namespace bg = boost::geometry;

namespace {

using Closed = bg::model::polygon<Point, false, true>;

void clip_into(const std::vector<Point>& ring, double s0, double s1, double t0, double t1,
               std::vector<Polygon>& out) {
  Closed poly;
  poly.outer().assign(ring.begin(), ring.end());
  poly.outer().push_back(ring.front());
  bg::correct(poly);
  if (std::abs(bg::area(poly)) <= 1e-14) return;
  const bg::model::box<Point> box(Point(s0, t0), Point(s1, t1));
  bg::model::multi_polygon<Closed> pieces;
  bg::intersection(poly, box, pieces);
  for (const auto& piece : pieces) {
    if (std::abs(bg::area(piece)) <= 1e-14) continue;
    Polygon p;
    p.outer().assign(piece.outer().begin(), piece.outer().end() - 1);
    out.push_back(std::move(p));
  }
}

// Tiles are clipped a little beyond their path segment. Clipping exactly at s_i would leave the
// line s = s_i on the boundary of two adjacent pieces, and a node waiting at a path vertex (a
// vertical s-t edge along that line) would slip through an obstacle unseen, since boundaries are
// passable. The overlap is conservative: it can only forbid a sliver more.
constexpr double kTileOverlap = 1e-5;

using Box = bg::model::box<Point>;

bool overlaps(const Box& a, const Box& b) {
  return a.min_corner().x() <= b.max_corner().x() && b.min_corner().x() <= a.max_corner().x() &&
         a.min_corner().y() <= b.max_corner().y() && b.min_corner().y() <= a.max_corner().y();
}

Box box_of(const std::vector<Point>& points) {
  Box b(points.front(), points.front());
  for (const auto& p : points) bg::expand(b, p);
  return b;
}

Point sub(const Point& a, const Point& b) { return Point(a.x() - b.x(), a.y() - b.y()); }
double norm(const Point& a) { return std::hypot(a.x(), a.y()); }

// Drops vertices that are collinear with their neighbours or reflex by less than a sliver (the
// kinks the tile overlap leaves on a merged boundary). Dropping a reflex vertex adds a triangle to
// the region, so the result still contains the input.
void drop_slivers(std::vector<Point>& ring) {
  bool changed = true;
  while (changed && ring.size() > 3) {
    changed = false;
    for (std::size_t i = 0; i < ring.size() && ring.size() > 3; ++i) {
      const Point& a = ring[(i + ring.size() - 1) % ring.size()];
      const Point& b = ring[i];
      const Point& c = ring[(i + 1) % ring.size()];
      const double chord = std::hypot(c.x() - a.x(), c.y() - a.y());
      const double cross = (b.x() - a.x()) * (c.y() - b.y()) - (b.y() - a.y()) * (c.x() - b.x());
      // Counter-clockwise ring: cross < 0 is a reflex vertex; its height over the chord is
      // |cross| / chord.
      if (chord > 0 && cross <= 0 && -cross <= 1e-7 * chord) {
        ring.erase(ring.begin() + static_cast<long>(i));
        changed = true;
      }
    }
  }
}

std::size_t find_root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

std::vector<Polygon> merge_regions(std::vector<Polygon> regions) {
  const std::size_t n = regions.size();
  if (n < 2) return regions;
  std::vector<Closed> closed(n);
  std::vector<Box> boxes(n);
  for (std::size_t i = 0; i < n; ++i) {
    closed[i].outer().assign(regions[i].outer().begin(), regions[i].outer().end());
    bg::correct(closed[i]);
    boxes[i] = bg::return_envelope<Box>(closed[i]);
  }
  // Groups of regions that meet (overlap or touch), by union-find over box-overlapping pairs.
  std::vector<std::size_t> parent(n);
  for (std::size_t i = 0; i < n; ++i) parent[i] = i;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      if (!overlaps(boxes[i], boxes[j]) || find_root(parent, i) == find_root(parent, j)) continue;
      if (bg::intersects(closed[i], closed[j])) parent[find_root(parent, j)] = find_root(parent, i);
    }
  }
  std::vector<std::vector<std::size_t>> groups(n);
  for (std::size_t i = 0; i < n; ++i) groups[find_root(parent, i)].push_back(i);
  std::vector<Polygon> result;
  for (const auto& group : groups) {
    if (group.empty()) continue;
    if (group.size() == 1) {
      result.push_back(std::move(regions[group.front()]));
      continue;
    }
    bg::model::multi_polygon<Closed> merged{closed[group.front()]};
    bool sound = true;
    try {
      for (std::size_t k = 1; k < group.size(); ++k) {
        bg::model::multi_polygon<Closed> next;
        bg::union_(merged, closed[group[k]], next);
        merged = std::move(next);
      }
    } catch (const bg::exception&) {
      sound = false;  // near-degenerate input: keep the pieces
    }
    // A forbidden region must never shrink: every piece keeps a point inside the union, and the
    // union is no smaller than its largest piece. Otherwise the pieces are kept as they are.
    const double merged_area = sound ? bg::area(merged) : 0.0;
    for (std::size_t k = 0; sound && k < group.size(); ++k) {
      Point inner;
      bg::point_on_surface(closed[group[k]], inner);
      sound = bg::covered_by(inner, merged) && merged_area >= bg::area(closed[group[k]]) - 1e-12;
    }
    const bool holes = std::any_of(merged.begin(), merged.end(),
                                   [](const Closed& p) { return !p.inners().empty(); });
    if (!sound || holes || merged.empty()) {
      for (std::size_t i : group) result.push_back(std::move(regions[i]));
      continue;
    }
    for (const auto& piece : merged) {
      std::vector<Point> ring(piece.outer().begin(), piece.outer().end() - 1);
      drop_slivers(ring);
      Polygon p;
      p.outer().assign(ring.begin(), ring.end());
      if (std::abs(bg::area(p)) > 1e-14) result.push_back(std::move(p));
    }
  }
  return result;
}

TileCase classify_tile(const Point& dx, const Point& v) {
  const double len = norm(dx);
  if (len <= kEpsilon) return TileCase::kStationary;
  const double det = dx.x() * v.y() - dx.y() * v.x();
  if (std::abs(det) <= 1e-12 * len * std::max(1.0, norm(v))) return TileCase::kParallel;
  return TileCase::kRegular;
}

ForbiddenRegions compute_forbidden_regions(const std::vector<Point>& path,
                                           const MovingObstacle& obstacle, double t_lo,
                                           double t_hi) {
  ForbiddenRegions result;
  const auto& traj = obstacle.trajectory.points();
  if (traj.empty() || path.empty() || t_hi < t_lo) return result;
  const double s_total = [&] {
    double s = 0;
    for (std::size_t i = 1; i < path.size(); ++i) s += distance(path[i - 1], path[i]);
    return s;
  }();
  // Obstacle segments clipped to the window; a single-waypoint trajectory is a zero-length span.
  struct Segment {
    double t0, t1;
    Point p0, v;
    Box swept;  // envelope of the obstacle during the segment (A.7 lines 9/14)
  };
  const auto shape_box = bg::return_envelope<Box>(obstacle.shape);
  std::vector<Segment> segments;
  const Box path_box = box_of(path);
  for (std::size_t j = 0; j + 1 < traj.size() || (traj.size() == 1 && j == 0); ++j) {
    const auto& a = traj[j];
    const auto& b = traj.size() == 1 ? traj[0] : traj[j + 1];
    const double t0 = std::max(a.t, t_lo);
    const double t1 = std::min(b.t, t_hi);
    if (t1 < t0) continue;
    Point v(0, 0);
    if (b.t > a.t) v = Point((b.x - a.x) / (b.t - a.t), (b.y - a.y) / (b.t - a.t));
    const Point p0 = obstacle.trajectory.position_at(t0);
    const Point p1(p0.x() + v.x() * (t1 - t0), p0.y() + v.y() * (t1 - t0));
    const Box swept(Point(std::min(p0.x(), p1.x()) + shape_box.min_corner().x(),
                          std::min(p0.y(), p1.y()) + shape_box.min_corner().y()),
                    Point(std::max(p0.x(), p1.x()) + shape_box.max_corner().x(),
                          std::max(p0.y(), p1.y()) + shape_box.max_corner().y()));
    // A.7 line 9: skip obstacle segments whose envelope misses the whole path.
    if (!overlaps(swept, path_box)) continue;
    segments.push_back({t0, t1, p0, v, swept});
  }

  if (s_total <= kEpsilon) {
    // Stationary case (eq. 4.16, 4.21): which times of each obstacle segment cover the point.
    const Point& x = path.front();
    for (const auto& seg : segments) {
      const Polygon o = translate(obstacle.shape, seg.p0.x(), seg.p0.y());
      if (norm(seg.v) <= 0 || seg.t1 <= seg.t0) {
        if (strictly_inside(x, o)) result.blocked_times.emplace_back(seg.t0, seg.t1);
        continue;
      }
      // Trace V = x - v·u, u ∈ [0, Δt]: where it lies in O(t_j) the point is covered at t_j + u.
      const Point minus_v(-seg.v.x(), -seg.v.y());
      for (auto [u0, u1] : line_inside_intervals(x, minus_v, o)) {
        u0 = std::max(u0, 0.0);
        u1 = std::min(u1, seg.t1 - seg.t0);
        if (u1 > u0) result.blocked_times.emplace_back(seg.t0 + u0, seg.t0 + u1);
      }
    }
    return result;
  }

  double s_i = 0;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Point dx = sub(path[i + 1], path[i]);
    const double len = norm(dx);
    if (len <= kEpsilon) continue;
    const Point e(dx.x() / len, dx.y() / len);
    const double s0 = s_i;
    const double s1 = s_i + len;
    s_i = s1;
    const Box segment_box = box_of({path[i], path[i + 1]});
    for (const auto& seg : segments) {
      if (seg.t1 <= seg.t0) continue;  // an instant blocks no area of the s–t plane
      if (!overlaps(seg.swept, segment_box)) continue;  // A.7 line 14
      const Polygon o = translate(obstacle.shape, seg.p0.x(), seg.p0.y());
      if (classify_tile(dx, seg.v) == TileCase::kRegular) {
        // eq. 4.18: [e_s, -v] (s - s_i, t - t_j)^T = p - x_i, solved for each obstacle corner.
        Eigen::Matrix2d a;
        a << e.x(), -seg.v.x(), e.y(), -seg.v.y();
        const Eigen::Matrix2d inv = a.inverse();
        std::vector<Point> ring;
        for (const auto& p : vertices(o)) {
          const Eigen::Vector2d st =
              inv * Eigen::Vector2d(p.x() - path[i].x(), p.y() - path[i].y());
          ring.emplace_back(s0 + st.x(), seg.t0 + st.y());
        }
        clip_into(ring, s0 - kTileOverlap, s1 + kTileOverlap, seg.t0, seg.t1, result.regions);
      } else {
        // Parallel case (eq. 4.19/4.20): the cut of the line g at t_j, shifted by (v·e_s)(t - t_j).
        const double w = seg.v.x() * e.x() + seg.v.y() * e.y();
        const double dt = seg.t1 - seg.t0;
        for (const auto& [a, b] : line_inside_intervals(path[i], e, o)) {
          // A point of g at offset u along e is covered at time t iff u - w(t - t_j) ∈ [a, b].
          const std::vector<Point> ring{Point(s0 + a, seg.t0), Point(s0 + b, seg.t0),
                                        Point(s0 + b + w * dt, seg.t1),
                                        Point(s0 + a + w * dt, seg.t1)};
          clip_into(ring, s0 - kTileOverlap, s1 + kTileOverlap, seg.t0, seg.t1, result.regions);
        }
      }
    }
  }
  result.regions = merge_regions(std::move(result.regions));
  return result;
}

}  // namespace oscar::swarm
