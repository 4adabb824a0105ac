// The running swarm's world: named obstacles in Unix time, and the planner's World made of them.
#include <gtest/gtest.h>

#include "../src/swarm/live_world.hpp"

namespace oscar::coordinator {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

SwarmObstacle obstacle(const std::string& name, std::vector<std::array<double, 3>> path = {},
                       std::int64_t loop_ns = 0) {
  SwarmObstacle o;
  o.name(name);
  o.shape().x({-1, 1, 1, -1});
  o.shape().y({-1, -1, 1, 1});
  for (const auto& [x, y, t] : path) {
    SwarmWaypoint w;
    w.x(x);
    w.y(y);
    w.t_ns(static_cast<std::int64_t>(t * 1e9));
    o.path().push_back(w);
  }
  o.loop_ns(loop_ns);
  return o;
}

void expect_refused(LiveWorld& world, SwarmObstacle o, const std::string& part) {
  const auto before = world.obstacles().size();
  try {
    world.add(std::move(o));
    FAIL() << "accepted; expected '" << part << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
  EXPECT_EQ(world.obstacles().size(), before);
}

TEST(LiveWorld, ALoopIsUnrolledOverTheSpanAskedInThePlannersTime) {
  LiveWorld world;
  world.add(obstacle("shelf"));
  // Round a 10 s loop: (0, 0) at 0, (10, 0) at 5, back at 10 — of Unix time modulo 10 s.
  world.add(obstacle("forklift", {{0, 0, 0}, {10, 0, 5}, {0, 0, 10}}, 10 * kS));
  EXPECT_TRUE(world.has_loops());
  const swarm_wire::Clock clock{1'700'000'003 * kS};  // 3 s into a round of the loop
  const auto w = world.planned(clock, 0, 30);
  ASSERT_EQ(w.static_obstacles.size(), 1u);
  ASSERT_EQ(w.dynamic_obstacles.size(), 1u);
  const auto& t = w.dynamic_obstacles[0].trajectory;
  EXPECT_LE(t.start_time(), 0);
  EXPECT_GE(t.end_time(), 30);
  // At planner time 2 it is Unix 1'700'000'005: 5 s into the round, at (10, 0).
  EXPECT_NEAR(t.position_at(2).x(), 10, 1e-9);
  EXPECT_NEAR(t.position_at(7).x(), 0, 1e-9);
  EXPECT_NEAR(t.position_at(24.5).x(), 5, 1e-9);  // 7.5 s into a round: half way back
}

TEST(LiveWorld, AFinitePathKeepsItsUnixTimes) {
  LiveWorld world;
  world.add(obstacle("cart", {{0, 0, 1'700'000'010}, {4, 0, 1'700'000'014}}));
  const swarm_wire::Clock clock{1'700'000'000 * kS};
  const auto w = world.planned(clock, 0, 1000);
  ASSERT_EQ(w.dynamic_obstacles.size(), 1u);
  EXPECT_NEAR(w.dynamic_obstacles[0].trajectory.start_time(), 10, 1e-6);
  EXPECT_NEAR(w.dynamic_obstacles[0].trajectory.end_time(), 14, 1e-6);
  EXPECT_FALSE(world.has_loops());
}

TEST(LiveWorld, BadObstaclesAreRefusedNamingTheRule) {
  LiveWorld world;
  world.add(obstacle("shelf"));
  expect_refused(world, obstacle("shelf"), "obstacle 'shelf': the world has one of that name");
  expect_refused(world, obstacle(""), "an obstacle's name has 1 to 128 characters");
  auto bow_tie = obstacle("tie");
  bow_tie.shape().x({0, 1, 1, 0});
  bow_tie.shape().y({0, 1, 0, 1});
  expect_refused(world, bow_tie, "self-intersecting");
  auto uneven = obstacle("uneven");
  uneven.shape().y({0, 1});
  expect_refused(world, uneven, "obstacle 'uneven' shape: 4 x but 2 y coordinates");
  expect_refused(world, obstacle("back", {{0, 0, 5}, {1, 0, 4}}), "path point 1 goes back");
  expect_refused(world, obstacle("one", {{0, 0, 5}}), "at least 2 points");
  expect_refused(world, obstacle("still", {{0, 0, 5}, {1, 0, 5}}), "lasts no time");
  expect_refused(world, obstacle("open", {{0, 0, 0}, {1, 0, 5}}, 5 * kS), "ends where it starts");
  expect_refused(world, obstacle("late", {{0, 0, 1}, {0, 0, 5}}, 5 * kS), "from t = 0");
  expect_refused(world, obstacle("neg", {{0, 0, 0}, {0, 0, 5}}, -5), "negative");
  EXPECT_THROW(world.remove("nothing"), std::invalid_argument);
  world.remove("shelf");
  EXPECT_TRUE(world.obstacles().empty());
}

}  // namespace
}  // namespace oscar::coordinator
