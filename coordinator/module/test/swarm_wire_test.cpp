// What a robot tells of its committed plan, in the planner's terms (swarm_wire::committed_plan),
// and job specifications both ways.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "../src/swarm/swarm_wire.hpp"
#include "oscar/swarm_yaml.hpp"

namespace oscar::coordinator {
namespace {

constexpr std::int64_t kEpoch = 1'700'000'000'000'000'000;
const swarm_wire::Clock kClock{kEpoch};
std::int64_t at_s(double s) { return kClock.ns(s); }

SwarmWaypoint wp(double x, double y, double t) {
  SwarmWaypoint w;
  w.x(x);
  w.y(y);
  w.t_ns(at_s(t));
  return w;
}

// r1 from (1, 0) at 2 s to (5, 0) at 6 s, where it works J from 8 s to 10 s (window [3, 20]).
Trajectory answer() {
  Trajectory t;
  t.robot("r1");
  TrajectorySection s;
  s.from_ns(at_s(2));
  s.to_ns(at_s(6));
  s.open_end(true);
  s.waypoints({wp(1, 0, 2), wp(5, 0, 6)});
  t.sections().push_back(s);
  RobotJob j;
  j.id("J");
  j.x(5);
  j.y(0);
  j.start_ns(at_s(8));
  j.end_ns(at_s(10));
  j.earliest_start_ns(at_s(3));
  j.latest_finish_ns(at_s(20));
  t.jobs_added().push_back(j);
  return t;
}

TEST(SwarmWire, ACommittedPlanInThePlannersTerms) {
  const auto plan = swarm_wire::committed_plan("r1", to_yaml(answer()), kClock);
  ASSERT_EQ(plan.trajectory.points().size(), 2u);
  EXPECT_DOUBLE_EQ(plan.trajectory.start_time(), 2);
  EXPECT_DOUBLE_EQ(plan.trajectory.position_at(4).x(), 3);
  ASSERT_EQ(plan.jobs.size(), 1u);
  const auto& j = plan.jobs[0];
  EXPECT_EQ(j.id, "J");
  EXPECT_EQ(j.node, "r1");
  EXPECT_DOUBLE_EQ(j.start, 8);
  EXPECT_DOUBLE_EQ(j.duration, 2);
  EXPECT_EQ(j.spec.id, "J");
  EXPECT_DOUBLE_EQ(j.spec.earliest_start, 3);
  EXPECT_DOUBLE_EQ(j.spec.latest_finish, 20);
  EXPECT_DOUBLE_EQ(j.spec.duration, 2);
  // Its place as a square of kTakenOverJobArea.
  EXPECT_TRUE(swarm::strictly_inside(swarm::Point(5, 0), j.spec.area));
  const auto corners = swarm::vertices(j.spec.area);
  ASSERT_EQ(corners.size(), 4u);
  for (const auto& c : corners) {
    EXPECT_NEAR(std::abs(c.x() - 5), swarm_wire::kTakenOverJobArea / 2, 1e-12);
    EXPECT_NEAR(std::abs(c.y()), swarm_wire::kTakenOverJobArea / 2, 1e-12);
  }
  EXPECT_FALSE(plan.idle());
}

TEST(SwarmWire, ARobotThatStandsForGoodWithNoJobIsIdle) {
  Trajectory t = answer();
  t.jobs_added().clear();
  EXPECT_FALSE(swarm_wire::committed_plan("r1", to_yaml(t), kClock).idle()) << "it still drives";
  t.sections()[0].waypoints({wp(1, 0, 2)});
  EXPECT_TRUE(swarm_wire::committed_plan("r1", to_yaml(t), kClock).idle());
}

TEST(SwarmWire, AnAnswerThatIsNoCommittedPlanIsRefusedWithTheRule) {
  auto error = [](const std::string& text) {
    try {
      swarm_wire::committed_plan("r1", text, kClock);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Trajectory other = answer();
  other.robot("r2");
  EXPECT_EQ(error(to_yaml(other)), "the committed plan names robot 'r2', not 'r1'");
  Trajectory closed = answer();
  closed.sections()[0].open_end(false);
  EXPECT_EQ(error(to_yaml(closed)),
            "a committed plan is one open-ended section with waypoints, from the robot's now on");
  Trajectory backwards = answer();
  backwards.sections()[0].waypoints({wp(1, 0, 6), wp(5, 0, 2)});
  EXPECT_NE(error(to_yaml(backwards)), "no error");
  Trajectory inverted = answer();
  inverted.jobs_added()[0].end_ns(at_s(7));
  EXPECT_EQ(error(to_yaml(inverted)),
            fmt::format("job 'J' ends at {} ns, before it starts at {} ns", at_s(7), at_s(8)));
  EXPECT_NE(error("{robot: [r1").find("trajectory: no YAML"), std::string::npos);
  EXPECT_NE(error("{robot: r1, sections: 3}").find("sections: expected a list"), std::string::npos);
}

TEST(SwarmWire, AJobSpecGoesToTheWireAndBack) {
  const swarm::JobSpec spec{"J", swarm::make_polygon({{0, 0}, {2, 0}, {2, 1}, {0, 1}}, "J area"), 3,
                            20, 2};
  const auto back = swarm_wire::job_spec(swarm_wire::wire_job_spec(spec, kClock), kClock);
  EXPECT_EQ(back.id, "J");
  EXPECT_DOUBLE_EQ(back.earliest_start, 3);
  EXPECT_DOUBLE_EQ(back.latest_finish, 20);
  EXPECT_DOUBLE_EQ(back.duration, 2);
  EXPECT_EQ(swarm::vertices(back.area).size(), 4u);
}

}  // namespace
}  // namespace oscar::coordinator
