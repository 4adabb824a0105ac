#include "pilot_trajectory.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace oscar::modules {
namespace {

constexpr Stamp kS = 1'000'000'000;  // ns

TEST(PilotTrajectory, StandsAtItsStartForGoodFacingItsHeading) {
  const PilotTrajectory t(1, 2, 0.5);
  for (const Stamp at : {Stamp{0}, 5 * kS, Stamp{1} << 62}) {
    const auto m = t.at(at);
    EXPECT_EQ(m.x, 1);
    EXPECT_EQ(m.y, 2);
    EXPECT_EQ(m.heading, 0.5);
    EXPECT_EQ(m.speed, 0);
  }
  EXPECT_EQ(t.transaction_at(5 * kS), 0u);
}

TEST(PilotTrajectory, PlaceAtInterpolatesAndClampsToTheEnds) {
  const std::vector<TimedPoint> p{{0, 0, 10}, {2, 4, 20}, {2, 4, 30}};
  EXPECT_EQ(place_at(p, 0).x, 0);
  EXPECT_EQ(place_at(p, 15).x, 1);
  EXPECT_EQ(place_at(p, 15).y, 2);
  EXPECT_EQ(place_at(p, 99).y, 4);
}

TEST(PilotTrajectory, AClosedSpliceReplacesOnlyItsSpan) {
  PilotTrajectory t(0, 0, 0);
  t.splice({{0, 0, 1 * kS}, {4, 0, 5 * kS}}, 1 * kS, 0, true, 1);  // drives to (4, 0), stays
  t.splice({{4, 0, 6 * kS}, {4, 1, 7 * kS}, {4, 0, 8 * kS}}, 6 * kS, 8 * kS, false, 2);
  EXPECT_DOUBLE_EQ(t.at(3 * kS).x, 2);
  EXPECT_EQ(t.transaction_at(3 * kS), 1u);
  EXPECT_DOUBLE_EQ(t.at(7 * kS).y, 1);
  EXPECT_EQ(t.transaction_at(7 * kS), 2u);
  EXPECT_DOUBLE_EQ(t.at(9 * kS).x, 4);
  EXPECT_DOUBLE_EQ(t.at(9 * kS).y, 0);
  EXPECT_EQ(t.transaction_at(9 * kS), 0u);
  EXPECT_EQ(t.transaction_at(5 * kS + 1), 0u) << "an open-ended section ends at its last waypoint";

  PilotTrajectory moving(0, 0, 0);  // a detour in the middle of a leg: the leg goes on after it
  moving.splice({{0, 0, 1 * kS}, {10, 0, 11 * kS}}, 1 * kS, 0, true, 1);
  moving.splice({{2, 0, 3 * kS}, {2, 1, 4 * kS}, {4, 0, 5 * kS}}, 3 * kS, 5 * kS, false, 2);
  EXPECT_DOUBLE_EQ(moving.at(2 * kS).x, 1);
  EXPECT_DOUBLE_EQ(moving.at(4 * kS).y, 1);
  EXPECT_DOUBLE_EQ(moving.at(8 * kS).x, 7);
  EXPECT_DOUBLE_EQ(moving.at(8 * kS).speed, 1);
  EXPECT_DOUBLE_EQ(moving.at(12 * kS).x, 10);
}

TEST(PilotTrajectory, AnOpenSpliceReplacesEverythingAfterItsStart) {
  PilotTrajectory t(0, 0, 0);
  t.splice({{0, 0, 1 * kS}, {0, 0, 2 * kS}, {1, 0, 3 * kS}, {1, 0, 4 * kS}, {0, 0, 5 * kS}}, 1 * kS,
           5 * kS, false, 1);
  t.splice({{1, 0, 3 * kS}, {1, 5, 8 * kS}}, 3 * kS, 0, true, 2);
  EXPECT_DOUBLE_EQ(t.at(5 * kS).y, 2) << "the old return to (0, 0) is gone";
  EXPECT_DOUBLE_EQ(t.at(20 * kS).y, 5);
  EXPECT_EQ(t.transaction_at(2 * kS), 1u);
  EXPECT_EQ(t.transaction_at(3 * kS), 2u) << "where sections touch, the later splice holds";
  EXPECT_EQ(t.transaction_at(4 * kS), 2u) << "section 1's span was cut where section 2 begins";
}

TEST(PilotTrajectory, HeadingIsTheDirectionOfMotionAndIsKeptWhileStanding) {
  PilotTrajectory t(0, 0, 1.0);
  t.splice({{0, 0, 1 * kS}, {0, 2, 3 * kS}, {0, 2, 4 * kS}, {-1, 2, 5 * kS}}, 1 * kS, 0, true, 1);
  EXPECT_DOUBLE_EQ(t.at(0).heading, 1.0);
  EXPECT_DOUBLE_EQ(t.at(1 * kS).heading, M_PI / 2) << "at a vertex the segment starting counts";
  EXPECT_DOUBLE_EQ(t.at(1 * kS).speed, 1);
  EXPECT_DOUBLE_EQ(t.at(3 * kS + kS / 2).heading, M_PI / 2);
  EXPECT_EQ(t.at(3 * kS + kS / 2).speed, 0);
  EXPECT_DOUBLE_EQ(t.at(4 * kS + kS / 2).heading, M_PI);
  EXPECT_DOUBLE_EQ(t.at(9 * kS).heading, M_PI);
  EXPECT_EQ(t.at(9 * kS).speed, 0);
}

TEST(PilotTrajectory, ForgettingThePastChangesNothingFromThenOn) {
  PilotTrajectory t(0, 0, 0);
  t.splice({{0, 0, 1 * kS}, {0, 2, 3 * kS}, {0, 2, 4 * kS}, {-1, 2, 5 * kS}}, 1 * kS, 0, true, 1);
  PilotTrajectory kept = t;
  kept.forget_before(4 * kS + kS / 10);
  EXPECT_LT(kept.points().size(), t.points().size());
  for (Stamp at = 4 * kS + kS / 10; at < 7 * kS; at += kS / 10) {
    EXPECT_EQ(kept.at(at).x, t.at(at).x);
    EXPECT_EQ(kept.at(at).y, t.at(at).y);
    EXPECT_EQ(kept.at(at).heading, t.at(at).heading);
    EXPECT_EQ(kept.at(at).speed, t.at(at).speed);
    EXPECT_EQ(kept.transaction_at(at), t.transaction_at(at));
  }
  PilotTrajectory standing = t;
  standing.forget_before(3 * kS + kS / 2);  // stands at (0, 2), facing up
  EXPECT_DOUBLE_EQ(standing.at(3 * kS + kS / 2).heading, M_PI / 2);
}

TEST(PilotTrajectory, FromATimeOnIsItsPlaceThenAndTheWaypointsAfter) {
  PilotTrajectory t(0, 0, 0);
  t.splice({{0, 0, 1 * kS}, {0, 2, 3 * kS}, {-1, 2, 4 * kS}}, 1 * kS, 0, true, 1);
  const std::vector<TimedPoint> rest{{0, 1, 2 * kS}, {0, 2, 3 * kS}, {-1, 2, 4 * kS}};
  EXPECT_EQ(t.from(2 * kS), rest);
  const std::vector<TimedPoint> at_vertex{{0, 2, 3 * kS}, {-1, 2, 4 * kS}};
  EXPECT_EQ(t.from(3 * kS), at_vertex);
  const std::vector<TimedPoint> standing{{-1, 2, 9 * kS}};
  EXPECT_EQ(t.from(9 * kS), standing);
  const std::vector<TimedPoint> before{{0, 0, 0}, {0, 0, 1 * kS}, {0, 2, 3 * kS}, {-1, 2, 4 * kS}};
  EXPECT_EQ(t.from(0), before);
}

TEST(PilotTrajectory, StoppingFreezesPlaceAndHeading) {
  PilotTrajectory t(0, 0, 0);
  t.splice({{0, 0, 1 * kS}, {0, 2, 3 * kS}}, 1 * kS, 0, true, 1);
  t.stop_at(2 * kS);
  EXPECT_DOUBLE_EQ(t.at(9 * kS).y, 1);
  EXPECT_DOUBLE_EQ(t.at(9 * kS).heading, M_PI / 2);
  EXPECT_EQ(t.at(9 * kS).speed, 0);
  EXPECT_EQ(t.transaction_at(2 * kS), 0u);
}

}  // namespace
}  // namespace oscar::modules
