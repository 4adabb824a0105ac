#include "monitor_obstacles.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "world_builder.hpp"

namespace oscar::modules::safety {
namespace {
using testing::HasSubstr;
using testing::ThrowsMessage;
using world_builder::area;
using world_builder::obstacle;
using world_builder::waypoint;
using world_builder::world;

constexpr std::int64_t kSecond = 1'000'000'000;
constexpr std::int64_t kT0 = 1'700'000'000 * kSecond;

const SwarmArea kUnitSquare = area({{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}});

TEST(MonitorObstacles, AWorldSplitsIntoStaticAndMovingObstaclesKeepingNamesAndSince) {
  const auto o = obstacles_of(world({
      obstacle("pallet", area({{0, 0}, {1, 0}, {1, 1}}), {}, 0, kT0),
      obstacle("cart", kUnitSquare, {waypoint(0, 0, kT0), waypoint(4, 0, kT0 + 4 * kSecond)}),
      obstacle("forklift", kUnitSquare,
               {waypoint(0, 0, 0), waypoint(2, 0, 5 * kSecond), waypoint(0, 0, 10 * kSecond)},
               10 * kSecond),
  }));
  ASSERT_EQ(o.static_obstacles.size(), 1u);
  EXPECT_EQ(o.static_obstacles[0].name, "pallet");
  EXPECT_EQ(o.static_obstacles[0].polygon.size(), 3u);
  EXPECT_FALSE(o.static_obstacles[0].counts_at(kT0 - 1));
  EXPECT_TRUE(o.static_obstacles[0].counts_at(kT0));
  ASSERT_EQ(o.moving_obstacles.size(), 2u);
  EXPECT_EQ(o.moving_obstacles[0].name, "cart");
  EXPECT_EQ(o.moving_obstacles[0].period_ns, 0);
  EXPECT_EQ(o.moving_obstacles[1].name, "forklift");
  EXPECT_EQ(o.moving_obstacles[1].period_ns, 10 * kSecond);
}

TEST(MonitorObstacles, APathDrivenOnceHasItsObstacleOnlyWhileItLasts) {
  const auto cart =
      obstacles_of(world({obstacle("cart", kUnitSquare,
                                   {waypoint(0, 0, kT0), waypoint(4, 0, kT0 + 4 * kSecond)})}))
          .moving_obstacles.at(0);
  EXPECT_EQ(cart.origin_at(kT0 - 1), std::nullopt);
  ASSERT_TRUE(cart.origin_at(kT0));
  EXPECT_DOUBLE_EQ(cart.origin_at(kT0)->x, 0);
  // Nanoseconds after a Unix time of 1.7e9 s still move it: no precision lost to doubles.
  EXPECT_DOUBLE_EQ(cart.origin_at(kT0 + 2 * kSecond + 500)->x, 2.0000005);
  EXPECT_DOUBLE_EQ(cart.path_time_s(kT0 + 2 * kSecond), 2);
  EXPECT_DOUBLE_EQ(cart.origin_at(kT0 + 4 * kSecond)->x, 4) << "the last point still counts";
  EXPECT_EQ(cart.origin_at(kT0 + 4 * kSecond + 1), std::nullopt);
}

TEST(MonitorObstacles, ALoopRepeatsForGoodFromSinceOn) {
  const auto forklift =
      obstacles_of(world({obstacle("forklift", kUnitSquare,
                                   {waypoint(0, 0, 0), waypoint(2, 0, 5 * kSecond),
                                    waypoint(0, 0, 10 * kSecond)},
                                   10 * kSecond, kT0)}))
          .moving_obstacles.at(0);
  EXPECT_EQ(forklift.origin_at(kT0 - 1), std::nullopt) << "before since_ns";
  EXPECT_DOUBLE_EQ(forklift.origin_at(kT0 + 5 * kSecond)->x, 2);  // kT0 is a multiple of 10 s
  EXPECT_DOUBLE_EQ(forklift.origin_at(kT0 + 1000 * kSecond + 5 * kSecond)->x, 2);
  EXPECT_DOUBLE_EQ(forklift.path_time_s(kT0 + 1000 * kSecond + 5 * kSecond), 5);
}

TEST(MonitorObstacles, ObstacleLabelsQuoteNamesAndNumberTheUnnamed) {
  EXPECT_EQ(obstacle_label("pallet", 3), "'pallet'");
  EXPECT_EQ(obstacle_label("", 3), "3");
}

TEST(MonitorObstacles, ABadWorldIsRefusedNamingTheObstacleAndTheRule) {
  auto refused = [](const std::vector<SwarmObstacle>& obstacles, const std::string& message) {
    EXPECT_THAT([&] { obstacles_of(world(obstacles)); },
                ThrowsMessage<std::invalid_argument>(HasSubstr(message)))
        << message;
  };
  const auto square = obstacle("ok", kUnitSquare);
  refused({square, obstacle("", kUnitSquare)}, "world: obstacle 1: it has no name");
  refused({square, obstacle("ok", kUnitSquare)},
          "world: obstacle 'ok': obstacles 0 and 1 share the name (names are unique)");
  SwarmArea ragged = kUnitSquare;
  ragged.y().pop_back();
  refused({obstacle("a", ragged)}, "world: obstacle 'a': its shape has 4 x and 3 y");
  refused({obstacle("a", area({{0, 0}, {1, 0}}))},
          "its shape has 2 vertices, a polygon at least 3");
  refused({obstacle("a", area({{0, 0}, {1, 0}, {1, std::numeric_limits<double>::quiet_NaN()}}))},
          "vertex 2 of its shape is not finite");
  refused({obstacle("bow", area({{0, 0}, {1, 1}, {1, 0}, {0, 1}}))},
          "world: obstacle 'bow': its shape meets itself at edges 0 and 2 (a polygon must not "
          "intersect itself)");
  refused({obstacle("a", kUnitSquare, {}, kSecond)},
          "loop_ns is 1000000000 but it has no path (a static obstacle has loop_ns 0)");
  refused({obstacle("a", kUnitSquare, {waypoint(0, 0, 0)}, -1)}, "loop_ns is -1");
  refused({obstacle("a", kUnitSquare, {}, 0, -5)}, "since_ns is -5 (0: from the start)");
  refused({obstacle("a", kUnitSquare, {waypoint(0, 0, kT0), waypoint(1, 0, kT0 - 1)})},
          "world: obstacle 'a': path point 1 goes back in time");
  refused(
      {obstacle("a", kUnitSquare,
                {waypoint(0, 0, kT0), waypoint(std::numeric_limits<double>::infinity(), 0, kT0)})},
      "path point 1 is not finite");
  refused({obstacle("a", kUnitSquare, {waypoint(0, 0, 1), waypoint(0, 0, kSecond)}, kSecond)},
          "its loop starts at t_ns 0, not 1");
  refused({obstacle("a", kUnitSquare, {waypoint(0, 0, 0), waypoint(0, 0, kSecond)}, 2 * kSecond)},
          "its loop ends at t_ns 1000000000, not at loop_ns 2000000000");
  refused({obstacle("a", kUnitSquare, {waypoint(0, 0, 0), waypoint(1, 0, kSecond)}, kSecond)},
          "world: obstacle 'a': its loop's first and last points differ: (0.000, 0.000) and "
          "(1.000, 0.000) (a loop ends where it starts)");
}

}  // namespace
}  // namespace oscar::modules::safety
