#pragma once
/// @file
/// Plane geometry shared by the swarm planner (seed 002 §4.3): points, polygons and the few exact
/// predicates the visibility graph and the s–t graph need. Polygons are Boost.Geometry models.

#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>
#include <string>
#include <vector>

namespace oscar::swarm {

/// A point in the plane (metres) or in the s–t plane (arc length, seconds).
using Point = boost::geometry::model::d2::point_xy<double>;
/// A simple polygon without holes, counter-clockwise, open ring (first vertex not repeated).
using Polygon = boost::geometry::model::polygon<Point, false, false>;

/// Distances below this count as touching (metres or seconds).
inline constexpr double kEpsilon = 1e-9;

/// Euclidean distance.
double distance(const Point& a, const Point& b);

/// The vertices of the polygon's outer ring.
const std::vector<Point>& vertices(const Polygon& polygon);

/// Builds a polygon from vertices, fixing orientation.
/// @throws std::invalid_argument naming `what` and the rule broken if there are fewer than 3
/// (distinct) vertices, a coordinate is not finite, the ring intersects itself or has a spike, or
/// the area is zero.
Polygon make_polygon(const std::vector<Point>& points, const std::string& what);

/// True if the point lies in the open interior, farther than kEpsilon from the boundary.
bool strictly_inside(const Point& p, const Polygon& polygon);

/// True if the closed segment a–b meets the open interior of the polygon (touching the boundary or
/// running along an edge is allowed: obstacles do not contain their boundary, seed §4.3.1 fn. 8).
bool segment_hits_interior(const Point& a, const Point& b, const Polygon& polygon);

/// Distance from point p to segment a–b.
double point_segment_distance(const Point& p, const Point& a, const Point& b);

/// The polygon grown outward by `distance_m` with mitred corners: a superset of the Minkowski sum
/// with a disc of that radius, so a point outside it keeps at least that distance (seed §4.3, fn.
/// 7).
Polygon inflate(const Polygon& polygon, double distance_m);

/// A regular octagon around the origin that contains the disc of radius `radius_m`.
Polygon disc_polygon(double radius_m);

/// The polygon translated by (dx, dy).
Polygon translate(const Polygon& polygon, double dx, double dy);

/// Sorted parameters u of the line p + u·d where it crosses polygon edges (d need not be unit).
std::vector<double> line_crossings(const Point& p, const Point& d, const Polygon& polygon);

/// Open parameter intervals [u0, u1] (u0 < u1) of the line p + u·d that lie inside the polygon.
std::vector<std::pair<double, double>> line_inside_intervals(const Point& p, const Point& d,
                                                             const Polygon& polygon);

}  // namespace oscar::swarm
