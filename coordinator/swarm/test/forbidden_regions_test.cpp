#include "oscar/swarm/forbidden_regions.hpp"

#include "oscar/swarm/trajectory_planner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <boost/geometry.hpp>

namespace oscar::swarm {
namespace {

namespace bg = boost::geometry;

Polygon unit_square() {
  return make_polygon({{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}, "shape");
}

MovingObstacle moving(double x0, double y0, double t0, double x1, double y1, double t1) {
  return {unit_square(), Trajectory({{x0, y0, t0}, {x1, y1, t1}})};
}

double total_area(const ForbiddenRegions& r) {
  double a = 0;
  for (const auto& p : r.regions) a += std::abs(bg::area(p));
  return a;
}

bool contains_vertex(const ForbiddenRegions& r, double s, double t) {
  for (const auto& p : r.regions) {
    for (const auto& v : vertices(p)) {
      if (std::abs(v.x() - s) < 1e-9 && std::abs(v.y() - t) < 1e-9) return true;
    }
  }
  return false;
}

const std::vector<Point> kPath{{0, 0}, {10, 0}};

TEST(ForbiddenRegions, RegularCaseCrossingAtRightAnglesIsASquare) {
  // The square crosses the path at x = 5 between t = 4.5 and 5.5.
  const auto r = compute_forbidden_regions(kPath, moving(5, -5, 0, 5, 5, 10), 0, 20);
  EXPECT_EQ(classify_tile({10, 0}, {0, 1}), TileCase::kRegular);
  EXPECT_NEAR(total_area(r), 1.0, 1e-9);
  EXPECT_TRUE(contains_vertex(r, 4.5, 4.5));
  EXPECT_TRUE(contains_vertex(r, 5.5, 5.5));
}

TEST(ForbiddenRegions, RegularCaseCrossingDiagonallyIsAParallelogram) {
  // v = (1, 1): s is blocked iff |s - t| < 0.5 while |t - 5| < 0.5.
  const auto r = compute_forbidden_regions(kPath, moving(0, -5, 0, 10, 5, 10), 0, 20);
  EXPECT_NEAR(total_area(r), 1.0, 1e-9);
  EXPECT_TRUE(contains_vertex(r, 4, 4.5));
  EXPECT_TRUE(contains_vertex(r, 5, 4.5));
  EXPECT_TRUE(contains_vertex(r, 6, 5.5));
  EXPECT_TRUE(contains_vertex(r, 5, 5.5));
}

TEST(ForbiddenRegions, RegionIsClippedToTheTimeWindow) {
  const auto r = compute_forbidden_regions(kPath, moving(5, -5, 0, 5, 5, 10), 5, 20);
  EXPECT_NEAR(total_area(r), 0.5, 1e-9);
}

TEST(ForbiddenRegions, ParallelCaseShiftsTheCutAlongThePath) {
  // Moving along the path with v = 1 from x = 2 to x = 6 during [0, 4].
  const auto r = compute_forbidden_regions(kPath, moving(2, 0, 0, 6, 0, 4), 0, 20);
  EXPECT_EQ(classify_tile({10, 0}, {1, 0}), TileCase::kParallel);
  EXPECT_NEAR(total_area(r), 4.0, 1e-9);
  EXPECT_TRUE(contains_vertex(r, 1.5, 0));
  EXPECT_TRUE(contains_vertex(r, 2.5, 0));
  EXPECT_TRUE(contains_vertex(r, 6.5, 4));
  EXPECT_TRUE(contains_vertex(r, 5.5, 4));
}

TEST(ForbiddenRegions, ParallelCaseWithAStandingObstacleIsARectangle) {
  const auto r = compute_forbidden_regions(kPath, moving(5, 0, 0, 5, 0, 10), 0, 20);
  EXPECT_EQ(classify_tile({10, 0}, {0, 0}), TileCase::kParallel);
  EXPECT_NEAR(total_area(r), 10.0, 1e-9);
  EXPECT_TRUE(contains_vertex(r, 4.5, 0));
  EXPECT_TRUE(contains_vertex(r, 5.5, 10));
}

TEST(ForbiddenRegions, PathSegmentsMakeTiles) {
  // An L-shaped path: the obstacle crossing x = 5 meets only the first segment.
  const std::vector<Point> path{{0, 0}, {10, 0}, {10, 10}};
  const auto r = compute_forbidden_regions(path, moving(5, -5, 0, 5, 5, 10), 0, 20);
  EXPECT_NEAR(total_area(r), 1.0, 1e-9);
  // Crossing the second segment (s in [10, 20]) at y = 5, i.e. s = 15, at t = 5.
  const auto r2 = compute_forbidden_regions(path, moving(5, 5, 0, 15, 5, 10), 0, 20);
  EXPECT_NEAR(total_area(r2), 1.0, 1e-9);
  EXPECT_TRUE(contains_vertex(r2, 14.5, 4.5));
}

// Regression (found by the property test, seed 4): a node waiting at the end of its path while an
// obstacle crosses it must meet the region's interior, not slip along a clipped boundary.
TEST(ForbiddenRegions, PathEndsAndVerticesLieInsideTheRegionWhenCovered) {
  const auto r = compute_forbidden_regions(kPath, moving(10, -5, 0, 10, 5, 10), 0, 20);
  bool end_inside = false;
  for (const auto& p : r.regions) end_inside = end_inside || strictly_inside({10, 5}, p);
  EXPECT_TRUE(end_inside);
  const std::vector<Point> bent{{0, 0}, {5, 0}, {5, 5}};
  const auto v = compute_forbidden_regions(bent, moving(5, -5, 0, 5, 5, 10), 0, 20);
  bool vertex_inside = false;
  for (const auto& p : v.regions) vertex_inside = vertex_inside || strictly_inside({5, 5}, p);
  EXPECT_TRUE(vertex_inside);
}

TEST(ForbiddenRegions, StationaryCaseGivesBlockedTimes) {
  EXPECT_EQ(classify_tile({0, 0}, {0, 1}), TileCase::kStationary);
  const auto r = compute_forbidden_regions({{5, 0}}, moving(5, -5, 0, 5, 5, 10), 0, 20);
  ASSERT_EQ(r.blocked_times.size(), 1u);
  EXPECT_NEAR(r.blocked_times[0].first, 4.5, 1e-9);
  EXPECT_NEAR(r.blocked_times[0].second, 5.5, 1e-9);
  EXPECT_TRUE(r.regions.empty());
}

TEST(ForbiddenRegions, StationaryCaseWithAStandingObstacleBlocksItsWholeSpan) {
  const auto r = compute_forbidden_regions({{5, 0.2}}, moving(5, 0, 2, 5, 0, 7), 0, 20);
  ASSERT_EQ(r.blocked_times.size(), 1u);
  EXPECT_NEAR(r.blocked_times[0].first, 2, 1e-9);
  EXPECT_NEAR(r.blocked_times[0].second, 7, 1e-9);
  const auto miss = compute_forbidden_regions({{5, 0.7}}, moving(5, 0, 2, 5, 0, 7), 0, 20);
  EXPECT_TRUE(miss.blocked_times.empty());
}

bool has_exactly(const Polygon& p, std::vector<Point> expected) {
  if (vertices(p).size() != expected.size()) return false;
  for (const auto& e : expected) {
    bool found = false;
    for (const auto& v : vertices(p)) found = found || distance(v, e) < 1e-6;
    if (!found) return false;
  }
  return true;
}

Polygon rect(double s0, double t0, double s1, double t1) {
  return make_polygon({{s0, t0}, {s1, t0}, {s1, t1}, {s0, t1}}, "rect");
}

// A.7 line 36 (forbidden ← forbidden ∪ f): the tiles of two path segments are one region again.
TEST(ForbiddenRegions, TilesOfCollinearPathSegmentsMergeIntoOneSquare) {
  const std::vector<Point> split{{0, 0}, {5, 0}, {10, 0}};
  const auto r = compute_forbidden_regions(split, moving(5, -5, 0, 5, 5, 10), 0, 20);
  ASSERT_EQ(r.regions.size(), 1u);
  EXPECT_TRUE(has_exactly(r.regions[0], {{4.5, 4.5}, {5.5, 4.5}, {5.5, 5.5}, {4.5, 5.5}}));
  EXPECT_NEAR(total_area(r), 1.0, 1e-9);
}

TEST(ForbiddenRegions, TilesOfObstacleTrajectorySegmentsMergeIntoOneSquare) {
  const MovingObstacle o{unit_square(), Trajectory({{5, -5, 0}, {5, 0, 5}, {5, 5, 10}})};
  const auto r = compute_forbidden_regions(kPath, o, 0, 20);
  ASSERT_EQ(r.regions.size(), 1u);
  EXPECT_TRUE(has_exactly(r.regions[0], {{4.5, 4.5}, {5.5, 4.5}, {5.5, 5.5}, {4.5, 5.5}}));
}

TEST(ForbiddenRegions, OverlappingRegionsMergeIntoTheirUnion) {
  const auto merged = merge_regions({rect(0, 0, 2, 2), rect(1, 1, 3, 3)});
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_TRUE(
      has_exactly(merged[0], {{0, 0}, {2, 0}, {2, 1}, {3, 1}, {3, 3}, {1, 3}, {1, 2}, {0, 2}}));
  EXPECT_NEAR(bg::area(merged[0]), 7.0, 1e-12);
}

TEST(ForbiddenRegions, RegionsTouchingAtAPointOrApartStaySeparate) {
  EXPECT_EQ(merge_regions({rect(0, 0, 1, 1), rect(1, 1, 2, 2)}).size(), 2u);
  EXPECT_EQ(merge_regions({rect(0, 0, 1, 1), rect(3, 3, 4, 4)}).size(), 2u);
}

TEST(ForbiddenRegions, AUnionWithAHoleKeepsItsPieces) {
  // Four bars around the free pocket [1, 2]²: a Polygon cannot hold the hole.
  const auto merged =
      merge_regions({rect(0, 0, 3, 1), rect(0, 2, 3, 3), rect(0, 0, 1, 3), rect(2, 0, 3, 3)});
  EXPECT_EQ(merged.size(), 4u);
}

// Correctness, not only speed: two standing obstacles side by side block s in [4, 6] during
// [5, 20]. Unmerged, a profile could wait on their shared edge s = 5 and arrive at 25. By hand:
// wait at s = 4 until 20, then 6 m at 1 m/s, arrival 26.
TEST(ForbiddenRegions, NoProfileWaitsOnTheSeamBetweenTwoObstacles) {
  std::vector<MovingObstacle> obstacles{{unit_square(), Trajectory({{4.5, 0, 5}, {4.5, 0, 20}})},
                                        {unit_square(), Trajectory({{5.5, 0, 5}, {5.5, 0, 20}})}};
  SpatialPathFinder free_space({});
  TrajectoryPlanner planner([&](const Point& a, const Point& b) { return free_space.find(a, b); },
                            obstacles, {1, 0, 0});
  const auto arrival = planner.earliest_arrival(kPath, 0, 100);
  ASSERT_TRUE(arrival.has_value());
  EXPECT_NEAR(*arrival, 26, 1e-6);
  VelocityPlanner seams(10, 0, {rect(4, 5, 5, 20), rect(5, 5, 6, 20)}, {1, 0, 0});
  EXPECT_FALSE(seams.free({5, 5}, {5, 20}));
}

}  // namespace
}  // namespace oscar::swarm
