#include "oscar/swarm/geometry.hpp"

#include <gtest/gtest.h>

#include <boost/geometry.hpp>
#include <cmath>
#include <stdexcept>

#include "expect_error.hpp"
#include "oscar/swarm/spatial_path_finder.hpp"

namespace oscar::swarm {
namespace {

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

TEST(Geometry, SegmentAlongAnEdgeDoesNotHitTheInterior) {
  const auto sq = square(0, 0, 1, 1);
  EXPECT_FALSE(segment_hits_interior({0, 0}, {1, 0}, sq));
  EXPECT_FALSE(segment_hits_interior({-1, 1}, {2, 1}, sq));
  EXPECT_TRUE(segment_hits_interior({0, 0}, {1, 1}, sq));  // the diagonal runs inside
  EXPECT_TRUE(segment_hits_interior({-1, 0.5}, {2, 0.5}, sq));
  EXPECT_FALSE(segment_hits_interior({2, 2}, {3, 3}, sq));
}

TEST(Geometry, BadPolygonsAreRejectedWithTheirNameAndTheRuleTheyBreak) {
  const auto expect_fault = [](const std::vector<Point>& points, const std::string& rule) {
    test::expect_error([&] { make_polygon(points, "job J1 area"); }, "job J1 area: " + rule);
  };
  // A symmetric bow-tie was reported as "wrong orientation": its loops cancel out.
  expect_fault({{0, 0}, {1, 1}, {1, 0}, {0, 1}}, "polygon is self-intersecting");
  expect_fault({{0, 0}, {2, 2}, {2, 0}, {0, 1}}, "polygon is self-intersecting");
  expect_fault({{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 1}}, "polygon is self-intersecting");
  expect_fault({{0, 0}, {2, 0}, {3, 0}, {2, 0}, {2, 1}, {0, 1}}, "polygon has a spike");
  expect_fault({{0, 0}, {1, 1}, {2, 2}}, "polygon has zero area");
  expect_fault({{0, 0}, {1e-12, 0}, {0, 1e-12}}, "polygon has zero area");
  expect_fault({{0, 0}, {0, 0}, {1, 1}}, "a polygon needs at least 3 distinct vertices");
  expect_fault({{0, 0}, {1, 1}}, "a polygon needs at least 3 vertices, got 2");
  expect_fault({{0, 0}, {1, std::nan("")}, {2, 0}}, "polygon coordinates must be finite");
  // Clockwise is turned, and a repeated first vertex is fine.
  EXPECT_GT(boost::geometry::area(make_polygon({{0, 0}, {0, 1}, {1, 1}, {1, 0}}, "cw")), 0);
  EXPECT_NO_THROW(make_polygon({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}}, "closed"));
}

TEST(Geometry, InflatedPolygonKeepsTheDistance) {
  const auto grown = inflate(square(0, 0, 1, 1), 0.5);
  for (const auto& v : vertices(grown)) {
    EXPECT_GE(std::max({-v.x(), v.x() - 1, -v.y(), v.y() - 1}), 0.5 - 1e-9);
  }
  EXPECT_TRUE(strictly_inside({-0.4, 0.5}, grown));
  EXPECT_FALSE(strictly_inside({-0.6, 0.5}, grown));
}

TEST(SpatialPathFinder, StraightLineWhenNothingIsInTheWay) {
  SpatialPathFinder finder({square(5, 5, 6, 6)});
  const auto path = finder.find({0, 0}, {3, 0});
  ASSERT_TRUE(path);
  EXPECT_EQ(path->size(), 2u);
  EXPECT_NEAR(path_length(*path), 3, 1e-12);
}

TEST(SpatialPathFinder, GoesAroundASquareByItsCorners) {
  SpatialPathFinder finder({square(1, -1, 2, 1)});
  const auto path = finder.find({0, 0}, {3, 0});
  ASSERT_TRUE(path);
  ASSERT_EQ(path->size(), 4u);
  EXPECT_NEAR(path_length(*path), 2 * std::sqrt(2.0) + 1, 1e-12);
}

TEST(SpatialPathFinder, NoPathIntoOrOutOfAnObstacle) {
  SpatialPathFinder finder({square(1, -1, 2, 1)});
  EXPECT_FALSE(finder.find({1.5, 0}, {3, 0}));
  // A closed ring of overlapping walls around the start.
  SpatialPathFinder walls({square(-2, -2, 2, -1), square(-2, 1, 2, 2), square(-2, -1.5, -1, 1.5),
                           square(1, -1.5, 2, 1.5)});
  EXPECT_FALSE(walls.find({0, 0}, {5, 5}));
}

}  // namespace
}  // namespace oscar::swarm
