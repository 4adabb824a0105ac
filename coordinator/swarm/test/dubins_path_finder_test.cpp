#include "oscar/swarm/dubins_path_finder.hpp"

#include <gtest/gtest.h>

#include <ompl/util/RandomNumbers.h>

#include "oscar/swarm/scheduler.hpp"
#include "oscar/swarm/spatial_path_finder.hpp"

namespace oscar::swarm {
namespace {

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

class DubinsPathFinderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { ompl::RNG::setSeed(7); }
};

TEST_F(DubinsPathFinderTest, MatchesTheExactPlannerWhereBothApply) {
  // Free space, headings along the line: a Dubins car drives straight.
  DubinsPathFinder dubins({}, {.turning_radius_m = 0.5, .iterations = 500, .resolution_m = 0.1});
  const auto path = dubins.find({0, 0}, {10, 0});
  ASSERT_TRUE(path);
  EXPECT_NEAR(dubins.last_length(), 10, 1e-6);
  EXPECT_NEAR(path_length(*path), 10, 1e-6);
}

// Regression (property test): a leg in -x direction has heading atan2(0, -1) = π, outside OMPL's
// SO2 bounds [-π, π); OMPL aborted on an assertion.
TEST_F(DubinsPathFinderTest, LegInNegativeXDirectionIsStraight) {
  DubinsPathFinder dubins({}, {.turning_radius_m = 0.5, .iterations = 500, .resolution_m = 0.1});
  const auto path = dubins.find({10, 0}, {0, 0});
  ASSERT_TRUE(path);
  EXPECT_NEAR(path_length(*path), 10, 1e-6);
}

TEST_F(DubinsPathFinderTest, AroundAnObstacleNoShorterThanExactAndClose) {
  const std::vector<Polygon> obstacles{square(4, -2, 6, 2)};
  SpatialPathFinder exact(obstacles);
  DubinsPathFinder dubins(
      obstacles,
      {.turning_radius_m = 0.5, .iterations = 3000, .restarts = 8, .resolution_m = 0.05});
  const auto e = exact.find({0, 0}, {10, 0});
  const auto d = dubins.find({0, 0}, {10, 0});
  ASSERT_TRUE(e);
  ASSERT_TRUE(d);
  const double le = path_length(*e);
  const double ld = path_length(*d);
  EXPECT_GE(ld, le - 1e-9);  // the exact planner is a lower bound
  EXPECT_LE(ld, 1.35 * le);  // and RRT with shortcutting gets near it
  for (std::size_t i = 1; i < d->size(); ++i) EXPECT_TRUE(exact.visible((*d)[i - 1], (*d)[i]));
  RecordProperty("exact_length", std::to_string(le));
  RecordProperty("dubins_length", std::to_string(ld));
  std::printf("exact %.3f m, dubins (r = 0.5 m) %.3f m\n", le, ld);
}

TEST_F(DubinsPathFinderTest, NoPathIntoAnObstacle) {
  DubinsPathFinder dubins({square(4, -2, 6, 2)},
                          {.turning_radius_m = 0.5, .iterations = 200, .resolution_m = 0.1});
  EXPECT_FALSE(dubins.find({0, 0}, {5, 0}));
}

TEST_F(DubinsPathFinderTest, SchedulerUsesItForNodesWithATurningRadius) {
  World w;
  w.static_obstacles.push_back(square(4, -2, 6, 2));
  Scheduler s(w, {});
  s.add_node({"car", 0.2, 1, 0, 0, 0, 0.5});
  const auto r = s.schedule(JobSpec{"J", square(9, -1, 11, 1), 0, 100, 5});
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  const auto& t = s.trajectory("car").points();
  EXPECT_GT(t.size(), 10u);  // a sampled curve, not the visibility graph's 4 corners
  SpatialPathFinder wall({inflate(square(4, -2, 6, 2), 0.2)});
  for (std::size_t i = 1; i < t.size(); ++i) {
    EXPECT_TRUE(wall.visible({t[i - 1].x, t[i - 1].y}, {t[i].x, t[i].y})) << "segment " << i;
  }
}

}  // namespace
}  // namespace oscar::swarm
