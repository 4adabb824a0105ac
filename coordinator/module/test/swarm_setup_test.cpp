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
  EXPECT_EQ(one.world.static_obstacles.size(), 1u);
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
}

}  // namespace
}  // namespace oscar::coordinator
