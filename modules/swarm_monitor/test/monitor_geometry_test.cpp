#include "monitor_geometry.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>

#include <gtest/gtest.h>

namespace oscar::modules::safety {
namespace {

// A unit square, counterclockwise, and an L: the square [0, 2]^2 without its corner (1, 2]^2.
const Polygon kSquare{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
const Polygon kL{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};

TEST(MonitorGeometry, SignedAreaIsPositiveCounterclockwiseNegativeClockwise) {
  EXPECT_DOUBLE_EQ(signed_area(kSquare), 1);
  EXPECT_DOUBLE_EQ(signed_area(Polygon(kSquare.rbegin(), kSquare.rend())), -1);
  EXPECT_DOUBLE_EQ(signed_area(kL), 3);
  EXPECT_DOUBLE_EQ(signed_area({{0, 0}, {1, 1}, {2, 2}}), 0);
}

TEST(MonitorGeometry, ContainsPointsInsideAndNotOutsideInEitherOrientation) {
  const Polygon clockwise(kL.rbegin(), kL.rend());
  for (const auto& polygon : {kL, clockwise}) {
    EXPECT_TRUE(contains(polygon, {0.5, 0.5}));
    EXPECT_TRUE(contains(polygon, {1.5, 0.5}));
    EXPECT_TRUE(contains(polygon, {0.5, 1.5}));
    EXPECT_FALSE(contains(polygon, {1.5, 1.5})) << "the L's missing corner";
    EXPECT_FALSE(contains(polygon, {-0.5, 0.5}));
    EXPECT_FALSE(contains(polygon, {2.5, 0.5}));
    EXPECT_FALSE(contains(polygon, {0.5, 2.5}));
    // A ray through the vertex (1, 1) and one along the edge y = 1 still count right.
    EXPECT_TRUE(contains(polygon, {0.5, 1}));
    EXPECT_FALSE(contains(polygon, {-1, 1}));
    EXPECT_FALSE(contains(polygon, {-1, 0}));
  }
  EXPECT_FALSE(contains({}, {0, 0}));
}

TEST(MonitorGeometry, DistanceToEdgesIsToTheNearestEdgeOrVertex) {
  EXPECT_DOUBLE_EQ(distance_to_segment({0, 0}, {2, 0}, {1, 3}), 3);   // foot on the segment
  EXPECT_DOUBLE_EQ(distance_to_segment({0, 0}, {2, 0}, {5, 4}), 5);   // beyond b: to b
  EXPECT_DOUBLE_EQ(distance_to_segment({0, 0}, {2, 0}, {-3, 4}), 5);  // before a: to a
  EXPECT_DOUBLE_EQ(distance_to_segment({1, 1}, {1, 1}, {4, 5}), 5);   // a point
  EXPECT_DOUBLE_EQ(distance_to_edges(kSquare, {0.5, 3}), 2);          // above the top edge
  EXPECT_DOUBLE_EQ(distance_to_edges(kSquare, {4, 5}), 5);            // to the corner (1, 1)
  EXPECT_DOUBLE_EQ(distance_to_edges(kSquare, {0.5, 0.25}), 0.25);    // inside: to the bottom
  EXPECT_DOUBLE_EQ(distance_to_edges(kL, {1.5, 1.5}), 0.5);           // in the L's notch
  EXPECT_TRUE(std::isinf(distance_to_edges({}, {0, 0})));
}

TEST(MonitorGeometry, DiscClearanceIsNegativeByHowFarTheDiscReachesIn) {
  // Outside: the gap between disc and polygon; touching: 0.
  EXPECT_NEAR(disc_clearance(kSquare, {0.5, 1.5}, 0.2), 0.3, 1e-12);
  EXPECT_NEAR(disc_clearance(kSquare, {0.5, 1.5}, 0.5), 0, 1e-12);
  // The centre outside, the disc reaching in.
  EXPECT_NEAR(disc_clearance(kSquare, {0.5, 1.5}, 0.7), -0.2, 1e-12);
  // The centre inside: the whole radius plus the way to the edge.
  EXPECT_NEAR(disc_clearance(kSquare, {0.5, 0.75}, 0.1), -0.35, 1e-12);
  // Near a corner from outside: distance to the vertex.
  EXPECT_NEAR(disc_clearance(kSquare, {1.3, 1.4}, 0.4), 0.1, 1e-12);
  EXPECT_NEAR(disc_clearance(kSquare, {1.3, 1.4}, 0.6), -0.1, 1e-12);
}

TEST(MonitorGeometry, SegmentsTouchWhenTheyCrossMeetAtAnEndOrOverlap) {
  EXPECT_TRUE(segments_touch({0, 0}, {2, 2}, {0, 2}, {2, 0}));     // an X
  EXPECT_TRUE(segments_touch({0, 0}, {2, 0}, {1, 0}, {1, 3}));     // a T: an end on the other
  EXPECT_TRUE(segments_touch({0, 0}, {2, 0}, {1, 0}, {3, 0}));     // collinear, overlapping
  EXPECT_TRUE(segments_touch({0, 0}, {2, 0}, {2, 0}, {3, 1}));     // end to end
  EXPECT_FALSE(segments_touch({0, 0}, {2, 0}, {3, 0}, {4, 0}));    // collinear, apart
  EXPECT_FALSE(segments_touch({0, 0}, {2, 0}, {1, 0.1}, {1, 3}));  // a T just short
  EXPECT_FALSE(segments_touch({0, 0}, {2, 2}, {0, 1}, {1, 2}));    // parallel
}

TEST(MonitorGeometry, SelfContactFindsTheEdgesWhereAPolygonMeetsItself) {
  using Edges = std::pair<std::size_t, std::size_t>;
  EXPECT_EQ(self_contact(kSquare), std::nullopt);
  EXPECT_EQ(self_contact(kL), std::nullopt);
  EXPECT_EQ(self_contact(Polygon(kL.rbegin(), kL.rend())), std::nullopt);
  EXPECT_EQ(self_contact({{0, 0}, {1, 0}, {0, 1}}), std::nullopt);
  // A bow-tie: the edges (0, 0)-(1, 1) and (1, 0)-(0, 1) cross.
  EXPECT_EQ(self_contact({{0, 0}, {1, 1}, {1, 0}, {0, 1}}), Edges(0, 2));
  // Two squares touching at the vertex (1, 1), drawn as one polygon.
  EXPECT_NE(self_contact({{0, 0}, {1, 0}, {1, 1}, {2, 1}, {2, 2}, {1, 2}, {1, 1}, {0, 1}}),
            std::nullopt);
  // Three collinear points: the closing edge runs back over the other two.
  EXPECT_EQ(self_contact({{0, 0}, {1, 0}, {2, 0}}), Edges(0, 2));
  // A spike: edge 1 runs back along edge 0.
  EXPECT_EQ(self_contact({{0, 0}, {2, 0}, {1, 0}, {1, 1}}), Edges(0, 1));
  // A vertex repeated: an edge of no length.
  EXPECT_NE(self_contact({{0, 0}, {1, 0}, {1, 0}, {1, 1}}), std::nullopt);
}

TEST(MonitorGeometry, TranslatedMovesEveryVertex) {
  const auto moved = translated(kSquare, {2, -1});
  ASSERT_EQ(moved.size(), 4u);
  EXPECT_DOUBLE_EQ(moved[0].x, 2);
  EXPECT_DOUBLE_EQ(moved[0].y, -1);
  EXPECT_DOUBLE_EQ(moved[2].x, 3);
  EXPECT_DOUBLE_EQ(moved[2].y, 0);
}

TEST(MonitorGeometry, LoopPositionIsLinearBetweenItsPoints) {
  // Out along x in 10 s, a jump to y = 1 at 10 s, back in 10 s.
  const std::vector<LoopPoint> loop{{0, 0, 0}, {8, 0, 10}, {8, 1, 10}, {0, 0, 20}};
  auto at = [&](double t) { return loop_position(loop, t); };
  EXPECT_DOUBLE_EQ(at(0).x, 0);
  EXPECT_DOUBLE_EQ(at(2.5).x, 2);
  EXPECT_DOUBLE_EQ(at(2.5).y, 0);
  EXPECT_DOUBLE_EQ(at(10).x, 8);
  EXPECT_DOUBLE_EQ(at(10).y, 1) << "where two points share a time, the later one holds";
  EXPECT_DOUBLE_EQ(at(15).x, 4);
  EXPECT_DOUBLE_EQ(at(15).y, 0.5);
  EXPECT_DOUBLE_EQ(at(20).x, 0);
  EXPECT_DOUBLE_EQ(at(-1).x, 0);
  EXPECT_DOUBLE_EQ(at(25).x, 0);
}

TEST(MonitorGeometry, LoopPhaseIsTheUnixTimeModuloThePeriod) {
  constexpr std::int64_t kPeriod = 20'000'000'000;  // 20 s
  constexpr std::int64_t kEpochStart = 1'700'000'000'000'000'000 / kPeriod * kPeriod;
  EXPECT_DOUBLE_EQ(loop_phase_s(kEpochStart, kPeriod), 0);
  EXPECT_DOUBLE_EQ(loop_phase_s(kEpochStart + 2'500'000'000, kPeriod), 2.5);
  EXPECT_DOUBLE_EQ(loop_phase_s(kEpochStart + 5 * kPeriod + 19'000'000'000, kPeriod), 19);
  EXPECT_DOUBLE_EQ(loop_phase_s(-1'000'000'000, kPeriod), 19) << "before the epoch, too";
}

}  // namespace
}  // namespace oscar::modules::safety
