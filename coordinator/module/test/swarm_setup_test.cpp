// The `coordinator: swarm:` section (docs/swarm.md, "The live swarm"): what it takes and how it
// refuses what it cannot use, naming the key and the rule at its line.
#include <gtest/gtest.h>

#include <string>

#include "oscar/coordinator/swarm_setup.hpp"

namespace oscar::coordinator {
namespace {

std::string system_with(const std::string& swarm) {
  return R"(
system: s
modules:
  - name: fleet
    kernels:
      - { type: robot_sim, name: r1 }
      - { type: robot_sim, name: r2, mode: { single_step: { trigger: module } } }
  - name: other
    kernels:
      - { type: bench_source, name: src, params: { type: Bool } }
coordinator:
  swarm:
)" + swarm;
}

SwarmSetup setup(const std::string& swarm) {
  const auto spec = SystemSpec::parse(YAML::Load(system_with(swarm)), "s.yaml");
  return SwarmSetup::from(spec).value();
}

void expect_refused(const std::string& swarm, const std::string& part) {
  try {
    setup(swarm);
    FAIL() << "accepted; expected '" << part << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(SwarmSetup, RobotsAreEveryRobotSimKernelUnlessNamed) {
  const auto all = setup("    frozen_horizon_ms: 1000\n");
  ASSERT_EQ(all.robots.size(), 2u);
  EXPECT_EQ(all.robots[0].kernel, "r1");
  EXPECT_EQ(all.robots[0].module, "fleet");
  const auto one =
      setup("    robots: [r2]\n    world: { static: [ [[0,0],[1,0],[1,1],[0,1]] ] }\n");
  ASSERT_EQ(one.robots.size(), 1u);
  EXPECT_EQ(one.robots[0].kernel, "r2");
  ASSERT_EQ(one.world.size(), 1u);
  EXPECT_EQ(one.world[0].name(), "static[0]");
  EXPECT_TRUE(one.world[0].path().empty());
  EXPECT_DOUBLE_EQ(one.settings.frozen_horizon, 1.0);
  EXPECT_EQ(one.ack_timeout.count(), 500);
}

TEST(SwarmSetup, ACoordinatorWithoutSwarmHasNone) {
  const auto spec = SystemSpec::parse(YAML::Load(R"(
system: s
modules:
  - name: fleet
    kernels:
      - { type: robot_sim, name: r1 }
coordinator:
  applets: []
)"),
                                      "s.yaml");
  EXPECT_FALSE(SwarmSetup::from(spec).has_value());
}

TEST(SwarmSetup, BadKeysAndValuesAreRefusedAtTheirLine) {
  expect_refused("    robots: [nobody]\n", "s.yaml:13: swarm.robots: no kernel named 'nobody'");
  expect_refused("    ack_timout_ms: 300\n", "ack_timout_ms");
  expect_refused("    replan_attempts: 2.5\n", "swarm.replan_attempts: expected a whole number");
  expect_refused("    location_samples: 0\n", "swarm.location_samples: expected a number in [1");
  expect_refused("    frozen_horizon_ms: 500\n    ack_timeout_ms: 400\n",
                 "frozen_horizon_ms (500) must cover a proposal and its commit");
  expect_refused("    world: { static: [ [[0,0],[1,1],[0,1],[1,0]] ] }\n", "self-intersecting");
  expect_refused("    monitors: [r9]\n", "swarm.monitors: no kernel named 'r9'");
  expect_refused(
      "    world: { dynamic: [ { shape: [[0,0],[1,0],[0,1]], trajectory: [[0,0,0]] } ] }\n",
      "goes round a loop in Unix time");
  expect_refused(
      "    world: { dynamic: [ { shape: [[0,0],[1,0],[0,1]], loop: [[0,0,0],[5,0,5]] } ] }\n",
      "world.dynamic[0]: obstacle 'world.dynamic[0]': a loop ends where it starts");
  expect_refused(
      "    world: { dynamic: [ { shape: [[0,0],[1,0],[0,1]], loop: [[0,0,1],[0,0,5]] } ] }\n",
      "a loop runs from t = 0");
  expect_refused(
      "    world: { dynamic: [ { shape: [[0,0],[1,0],[0,1]], loop: [[0,0,0],[0,0]] } ] }\n",
      "world.dynamic[0].loop: expected [x, y, t] of finite numbers");
  expect_refused(
      "    world: { static: [ [[0,0],[1,0],[0,1]] ], dynamic: [ { name: 'static[0]', "
      "shape: [[0,0],[1,0],[0,1]], loop: [[0,0,0],[0,0,5]] } ] }\n",
      "the world has one of that name already");
}

TEST(SwarmSetup, MovingObstaclesGoRoundLoopsInUnixTime) {
  const auto s = setup(
      "    world:\n      dynamic:\n        - { name: forklift, shape: "
      "[[-1,-1],[1,-1],[1,1],[-1,1]], "
      "loop: [[0,0,0],[10,0,5],[0,0,10]] }\n");
  ASSERT_EQ(s.world.size(), 1u);
  EXPECT_EQ(s.world[0].name(), "forklift");
  EXPECT_EQ(s.world[0].loop_ns(), 10'000'000'000);
  ASSERT_EQ(s.world[0].path().size(), 3u);
  EXPECT_EQ(s.world[0].path()[1].t_ns(), 5'000'000'000);
}

TEST(SwarmSetup, MonitorsAreEverySafetyMonitorKernelUnlessNamed) {
  EXPECT_TRUE(setup("    frozen_horizon_ms: 1000\n").monitors.empty());
  const auto named = setup("    monitors: [src]\n");
  ASSERT_EQ(named.monitors.size(), 1u);
  EXPECT_EQ(named.monitors[0].module, "other");
}

}  // namespace
}  // namespace oscar::coordinator
