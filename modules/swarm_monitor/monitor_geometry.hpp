#pragma once
/// @file The safety monitor's own plane geometry: a point in a polygon, the distance from a point
/// to a polygon's edges, how far a disc stays clear of a polygon, and a moving obstacle's place on
/// its loop. Written for the monitor alone: it checks the planner (coordinator/swarm) and so
/// shares none of its code.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace oscar::modules::safety {

struct Point {
  double x = 0;
  double y = 0;
};

/// A polygon's vertices in order (either orientation), not closed: the last vertex is not
/// repeated.
using Polygon = std::vector<Point>;

/// The polygon's area, positive when counterclockwise, negative when clockwise.
double signed_area(const Polygon& polygon);

/// Whether q lies inside the polygon (even-odd rule). A point on an edge may count either way;
/// callers that care measure its distance to the edges as well.
bool contains(const Polygon& polygon, Point q);

/// The distance from q to the segment a-b.
double distance_to_segment(Point a, Point b, Point q);

/// The distance from q to the nearest edge of the polygon (its boundary), inside or outside.
/// An empty polygon is infinitely far.
double distance_to_edges(const Polygon& polygon, Point q);

/// How far a disc stays clear of a polygon: the distance from its centre to the polygon's edges
/// minus its radius when the centre is outside; minus (that distance plus the radius) when it is
/// inside. Negative: the disc reaches into the polygon's interior by that much; 0: it touches.
double disc_clearance(const Polygon& polygon, Point centre, double radius);

/// Whether the closed segments a-b and c-d share at least one point (crossing, touching or
/// overlapping).
bool segments_touch(Point a, Point b, Point c, Point d);

/// Two edges where the polygon's boundary meets itself (edge i runs from vertex i to vertex
/// i + 1), or nothing if the polygon is simple. Consecutive edges may share their common vertex
/// and nothing more: one folding back along the other, or a vertex repeated, counts as meeting.
/// A polygon that meets itself has no well-defined inside for `contains` and `disc_clearance`.
std::optional<std::pair<std::size_t, std::size_t>> self_contact(const Polygon& polygon);

/// The polygon moved by `offset`.
Polygon translated(const Polygon& polygon, Point offset);

/// A point of a moving obstacle's loop: its origin is at (x, y) at loop time t (s).
struct LoopPoint {
  double x = 0;
  double y = 0;
  double t = 0;
};

/// Where a loop's origin is at loop time t (s): linear between the two loop points around t
/// (the later one where two share a time); before the first point the first, after the last the
/// last.
Point loop_position(const std::vector<LoopPoint>& loop, double t);

/// The loop time (s) at Unix time `now_ns` of a loop with period `period_ns` (> 0): the loop
/// starts again at every multiple of the period since the epoch, so it is `now_ns mod period`.
double loop_phase_s(std::int64_t now_ns, std::int64_t period_ns);

}  // namespace oscar::modules::safety
