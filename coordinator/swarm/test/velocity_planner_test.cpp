#include "oscar/swarm/velocity_planner.hpp"

#include <gtest/gtest.h>

namespace oscar::swarm {
namespace {

Polygon rect(double s0, double t0, double s1, double t1) {
  return make_polygon({{s0, t0}, {s1, t0}, {s1, t1}, {s0, t1}}, "region");
}

TEST(VelocityPlanner, EarliestArrivalAtFullSpeedWithoutRegions) {
  VelocityPlanner planner(10, 2, {}, {.v_max = 0.5});
  const auto profile = planner.earliest_arrival(100);
  ASSERT_TRUE(profile);
  EXPECT_NEAR(profile->back().y(), 22, 1e-9);
  EXPECT_NEAR(profile->back().x(), 10, 1e-12);
}

TEST(VelocityPlanner, EarliestArrivalWaitsForARegionAndDoesNotCrawl) {
  // The path is blocked at s in [4.5, 5.5] during t in [4.5, 8].
  VelocityPlanner planner(10, 0, {rect(4.5, 4.5, 5.5, 8)}, {.v_max = 1});
  const auto profile = planner.earliest_arrival(100);
  ASSERT_TRUE(profile);
  EXPECT_NEAR(profile->back().y(), 13.5, 1e-9);
  bool waited = false;
  for (std::size_t k = 1; k < profile->size(); ++k) {
    const double ds = (*profile)[k].x() - (*profile)[k - 1].x();
    const double dt = (*profile)[k].y() - (*profile)[k - 1].y();
    ASSERT_GT(dt, 0);
    const double v = ds / dt;
    EXPECT_TRUE(std::abs(v) < 1e-9 || std::abs(v - 1) < 1e-9) << "crawls at " << v;
    waited = waited || std::abs(v) < 1e-9;
  }
  EXPECT_TRUE(waited);
}

TEST(VelocityPlanner, FixedArrivalLaterThanNeededWaitsThenDrivesAtFullSpeed) {
  VelocityPlanner planner(4, 0, {}, {.v_max = 1});
  const auto profile = planner.fixed_arrival(10);
  ASSERT_TRUE(profile);
  ASSERT_EQ(profile->size(), 3u);
  EXPECT_NEAR((*profile)[1].x(), 0, 1e-12);
  EXPECT_NEAR((*profile)[1].y(), 6, 1e-9);
}

TEST(VelocityPlanner, ThresholdSuppressesShortWaitsButStillFindsAProfile) {
  VelocityPlanner planner(4, 0, {}, {.v_max = 1, .v_leave = 0, .wait_threshold_s = 7});
  const auto profile = planner.fixed_arrival(10);
  ASSERT_TRUE(profile);
  EXPECT_EQ(profile->size(), 2u);  // crawls at 0.4, the only edge left
}

TEST(VelocityPlanner, NoProfileWhenTheRegionBlocksTheWholePath) {
  VelocityPlanner planner(10, 0, {rect(0, 1, 10, 50)}, {.v_max = 1});
  EXPECT_FALSE(planner.earliest_arrival(40));
  EXPECT_FALSE(planner.fixed_arrival(20));
  EXPECT_TRUE(planner.earliest_arrival(100));  // after t = 50, s = 10 at t = 60
}

}  // namespace
}  // namespace oscar::swarm
