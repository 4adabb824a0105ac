#include "oscar/swarm/scheduler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "expect_error.hpp"
#include "schedule_checker.hpp"

namespace oscar::swarm {
namespace {

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

JobSpec job(const std::string& id, Polygon area, double t_min, double t_finish, double d) {
  return {id, std::move(area), t_min, t_finish, d};
}

// The set-up of seed §4.2.1 (Abb. 4.2/4.5): n1 is busy far away, n2 works at (3,1) until 20 and
// at (7,1) from 50. `t0` shifts every time (and the present) to test long horizons.
Scheduler worked_example(double t0 = 0) {
  Scheduler s({}, {.present = t0});
  s.add_node({"n1", 0.1, 0.5, 10, 10, t0, 0});
  s.add_node({"n2", 0.1, 0.5, 3, 1, t0, 0});
  for (const auto& spec : {job("X", square(9.9, 9.9, 10.1, 10.1), t0 + 5, t0 + 65, 60),
                           job("A", square(2.9, 0.9, 3.1, 1.1), t0 + 10, t0 + 20, 10),
                           job("B", square(6.9, 0.9, 7.1, 1.1), t0 + 50, t0 + 55, 5)}) {
    const auto r = s.schedule(spec);
    EXPECT_TRUE(r.ok) << r.reason;
    s.commit(r.transaction);  // an open transaction would lock the node's slot (§4.2.7)
  }
  EXPECT_EQ(s.jobs("n1").size(), 1u);
  EXPECT_EQ(s.jobs("n2").size(), 2u);
  return s;
}

TEST(Scheduler, WorkedExampleOfSection421PicksTheOnlyQualifyingPause) {
  Scheduler s = worked_example();
  const auto spec = job("J1", square(4, 2, 6, 4), 10, 60, 10);
  const auto slots = s.qualifying_slots(spec, Point(5, 3));
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_EQ(slots[0].node, "n2");
  EXPECT_DOUBLE_EQ(slots[0].t1, 20);
  EXPECT_DOUBLE_EQ(slots[0].t2, 50);
  EXPECT_NEAR(slots[0].detour, 2 * std::sqrt(8.0) - 4, 1e-12);
  EXPECT_NEAR(slots[0].detour, 1.66, 0.005);

  const auto result = s.schedule(spec);
  ASSERT_TRUE(result.ok) << result.reason;
  ASSERT_EQ(result.jobs.size(), 1u);
  const Job& j = result.jobs[0];
  EXPECT_EQ(j.node, "n2");
  EXPECT_DOUBLE_EQ(j.x, 5);
  EXPECT_DOUBLE_EQ(j.y, 3);
  EXPECT_NEAR(j.start, 20 + std::sqrt(8.0) / 0.5, 1e-9);  // straight there at full speed
  s.commit(result.transaction);
  const auto& t = s.trajectory("n2");
  const Point at_job = t.position_at(j.start + 5);
  EXPECT_NEAR(at_job.x(), 5, 1e-9);
  EXPECT_NEAR(at_job.y(), 3, 1e-9);
  const Point at_b = t.position_at(50);
  EXPECT_NEAR(at_b.x(), 7, 1e-9);
  EXPECT_NEAR(at_b.y(), 1, 1e-9);
}

// Seed §5.3.1: long horizons must not lose precision silently. Near the ±1e6 s limit the worked
// example gives the same slot and start to well below a microsecond (a double resolves ~1e-10 s
// there); beyond it the input is refused (BadInputGetsClearErrors).
TEST(Scheduler, WorkedExampleNearTheTimeLimitKeepsItsPrecision) {
  const double t0 = 999000;
  Scheduler s = worked_example(t0);
  const auto spec = job("J1", square(4, 2, 6, 4), t0 + 10, t0 + 60, 10);
  const auto slots = s.qualifying_slots(spec, Point(5, 3));
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_EQ(slots[0].node, "n2");
  EXPECT_NEAR(slots[0].detour, 2 * std::sqrt(8.0) - 4, 1e-9);
  const auto result = s.schedule(spec);
  ASSERT_TRUE(result.ok) << result.reason;
  EXPECT_NEAR(result.jobs[0].start - t0, 20 + std::sqrt(8.0) / 0.5, 1e-6);
  s.commit(result.transaction);
  const Point at_b = s.trajectory("n2").position_at(t0 + 50);
  EXPECT_NEAR(at_b.x(), 7, 1e-6);
  EXPECT_NEAR(at_b.y(), 1, 1e-6);
}

TEST(Scheduler, LoadFiguresOfTheWorkedExample) {
  Scheduler s = worked_example();
  // n2 over [0, 60]: jobs A [10,20] and B [50,55] = 15 s; driving (3,1)->(7,1) at 0.5 m/s = 8 s.
  const Load l = s.load("n2", 0, 60);
  EXPECT_NEAR(l.job, 15.0 / 60, 1e-12);
  EXPECT_NEAR(l.motion, 8.0 / 60, 1e-9);
  EXPECT_NEAR(l.stationary, 1 - 23.0 / 60, 1e-9);
  EXPECT_NEAR(l.total, 23.0 / 60, 1e-9);
  EXPECT_NEAR(l.velocity, 4.0 / (0.5 * 60), 1e-9);
  EXPECT_THROW(s.load("n2", 5, 5), std::invalid_argument);
}

TEST(Scheduler, InfeasibleJobIsAValueWithAReason) {
  Scheduler s = worked_example();
  const auto r = s.schedule(job("J1", square(4, 2, 6, 4), 10, 21, 10));  // nobody gets there
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("4.2-4.4"), std::string::npos) << r.reason;
  EXPECT_TRUE(s.open_transactions().empty());
  Scheduler empty({}, {});
  const auto none = empty.schedule(job("J2", square(4, 2, 6, 4), 10, 60, 10));
  EXPECT_EQ(none.reason, "job 'J2': no node is in planning");
}

// Two robots stand in a 1 m square, 0.35 m either side of its one sample (its middle): each
// blocks the sample for the other. The robot standing in the area does the job where it stands.
TEST(Scheduler, ARobotParkedInTheAreaDoesTheJobWhereItStandsWhenTheSamplesAreBlocked) {
  Scheduler s({}, {.present = 0, .frozen_horizon = 1, .location_samples = 1});
  s.add_node({"a", 0.3, 1, 0.15, 0.5, 0, 0});
  s.add_node({"b", 0.3, 1, 0.85, 0.5, 0, 0});
  s.add_node({"far", 0.3, 1, 10, 10, 0, 0});
  const auto r = s.schedule(job("J", square(0, 0, 1, 1), 2, 30, 3));
  ASSERT_TRUE(r.ok) << r.reason;
  ASSERT_EQ(r.jobs.size(), 1u);
  const auto& done = r.jobs.front();
  EXPECT_TRUE(done.node == "a" || done.node == "b") << done.node;
  const auto& stand = s.node(done.node);
  EXPECT_DOUBLE_EQ(done.x, stand.x);
  EXPECT_DOUBLE_EQ(done.y, stand.y);
}

TEST(Scheduler, UnscheduleReplansTheTrajectoryAroundTheGap) {
  Scheduler s = worked_example();
  const auto r = s.schedule(job("J1", square(4, 2, 6, 4), 10, 60, 10));
  ASSERT_TRUE(r.ok);
  s.commit(r.transaction);
  const auto u = s.unschedule("J1");
  ASSERT_TRUE(u.ok) << u.reason;
  s.commit(u.transaction);
  // From (3,1) straight to (7,1): never above y = 1 again.
  for (const auto& w : s.trajectory("n2").points()) EXPECT_NEAR(w.y, 1, 1e-9);
  EXPECT_EQ(s.jobs("n2").size(), 2u);
}

TEST(Scheduler, RemoveWithoutReplanningKeepsTheTrajectory) {
  Scheduler s = worked_example();
  const auto r = s.schedule(job("J1", square(4, 2, 6, 4), 10, 60, 10));
  ASSERT_TRUE(r.ok);
  s.commit(r.transaction);
  const auto before = s.trajectory("n2").points().size();
  const auto u = s.remove_job("J1");
  ASSERT_TRUE(u.ok);
  s.commit(u.transaction);
  EXPECT_EQ(s.trajectory("n2").points().size(), before);
  EXPECT_EQ(s.jobs("n2").size(), 2u);
}

TEST(Scheduler, RescheduleMovesTheJobAtomically) {
  Scheduler s = worked_example();
  const auto r = s.schedule(job("J1", square(4, 2, 6, 4), 10, 60, 10));
  ASSERT_TRUE(r.ok);
  s.commit(r.transaction);
  const auto moved = s.reschedule(job("J1", square(4, 0, 6, 2), 10, 60, 10));
  ASSERT_TRUE(moved.ok) << moved.reason;
  EXPECT_DOUBLE_EQ(moved.jobs[0].y, 1);
  const auto impossible = s.reschedule(job("J1", square(40, 0, 42, 2), 10, 60, 10));
  EXPECT_FALSE(impossible.ok);
  s.commit(moved.transaction);
  ASSERT_EQ(s.jobs("n2").size(), 3u);
  EXPECT_DOUBLE_EQ(s.jobs("n2")[1].y, 1);
}

TEST(Scheduler, FrozenHorizonProtectsThePast) {
  Scheduler s({}, {.present = 0, .frozen_horizon = 30});
  s.add_node({"n", 0.1, 1, 0, 0, 0, 0});
  const auto r = s.schedule(job("J", square(1, -1, 3, 1), 0, 20, 5));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("frozen horizon"), std::string::npos) << r.reason;
  const auto ok = s.schedule(job("K", square(1, -1, 3, 1), 0, 60, 5));
  ASSERT_TRUE(ok.ok);
  EXPECT_GE(ok.jobs[0].start, 30);
  EXPECT_NEAR(s.trajectory("n", false).position_at(30).x(), 0, 1e-12);
}

using test::expect_error;

TEST(Scheduler, BadInputGetsClearErrors) {
  Scheduler s({}, {});
  s.add_node({"n", 0.1, 1, 0, 0, 0, 0});
  expect_error([&] { s.schedule(job("J", square(1, 1, 2, 2), std::nan(""), 10, 1)); },
               "job 'J' earliest_start must be finite");
  expect_error([&] { s.schedule(job("J", square(1, 1, 2, 2), 0, INFINITY, 1)); },
               "latest_finish must be finite");
  expect_error([&] { s.schedule(job("J", square(1, 1, 2, 2), 0, 5, 10)); },
               "window [0, 5] is shorter than the duration 10");
  expect_error([&] { s.schedule(job("J", Polygon(), 0, 50, 10)); }, "job 'J' area");
  expect_error([&] { s.unschedule("nope"); }, "unknown job id 'nope'");
  expect_error([&] { s.commit(99); }, "unknown or finished transaction 99");
  expect_error([&] { s.add_node({"n", 0.1, 1, 5, 5, 0, 0}); }, "duplicate node id");
  expect_error([&] { s.add_node({"m", 0.1, 1, 0.1, 0, 0, 0}); }, "collides");
  expect_error([&] { s.add_node({"m", 0.1, 0, 5, 0, 0, 0}); }, "max_speed must be finite and > 0");
  expect_error([&] { s.schedule(job("J", square(1, 1, 2, 2), 0, 2e6, 1)); }, "§5.3.1");
  s.set_present(5);
  expect_error([&] { s.set_present(4); }, "present time must not go backwards");
  ASSERT_TRUE(s.schedule(job("J", square(1, 1, 2, 2), 0, 50, 1)).ok);
  expect_error([&] { s.schedule(job("J", square(1, 1, 2, 2), 0, 50, 1)); }, "already scheduled");
}

TEST(Scheduler, MovingObstacleMakesTheNodeWaitOrDodgeInTime) {
  World w;
  // A wall segment sweeping across the corridor x in [4, 6] during t in [0, 20].
  w.dynamic_obstacles.push_back({square(-1, -0.5, 1, 0.5), Trajectory({{5, -10, 0}, {5, 10, 20}})});
  Scheduler s(std::move(w), {});
  s.add_node({"n", 0.2, 1, 0, 0, 0, 0});
  const auto r = s.schedule(job("J", square(9, -1, 11, 1), 0, 100, 5));
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  // The obstacle (inflated) covers x=5 while |y - (t - 10)| < 0.7: the node must not be there.
  const auto& t = s.trajectory("n");
  for (double time = 0; time <= 20; time += 0.01) {
    const Point p = t.position_at(time);
    const double oy = time - 10;
    const bool hit = std::abs(p.x() - 5) < 1.2 && std::abs(p.y() - oy) < 0.7;
    ASSERT_FALSE(hit) << "collision at t=" << time;
  }
}

// Checks a node's trajectory against one moving square with the independent checker.
std::vector<std::string> clearance_violations(const Scheduler& s, const std::string& node,
                                              const MovingObstacle& o, double half) {
  check::Checker c;
  check::Body n{node, {}, s.node(node).radius_m, {}, true, s.node(node).max_speed_mps};
  for (const auto& w : s.trajectory(node).points()) n.trajectory.push_back({w.x, w.y, w.t});
  check::Body b{
      "obstacle", {{-half, -half}, {half, -half}, {half, half}, {-half, half}}, 0, {}, false, 0};
  for (const auto& w : o.trajectory.points()) b.trajectory.push_back({w.x, w.y, w.t});
  c.pair_clearance(n, b, 1000);
  c.speed(n);
  return c.violations;
}

// Regression: a node used to stay at its last job for good, so a job whose place a moving obstacle
// crosses long after the job was refused. A swarm developer expects the idle node to step aside.
TEST(Scheduler, IdleNodeStepsAsideForAnObstacleCrossingItsLastJobLater) {
  World w;
  const MovingObstacle crossing{square(-0.5, -0.5, 0.5, 0.5),
                                Trajectory({{5, -10, 100}, {5, 10, 120}})};
  w.dynamic_obstacles.push_back(crossing);
  Scheduler s(std::move(w), {});
  s.add_node({"n", 0.2, 1, 0, 0, 0, 0});
  const auto r = s.schedule(job("J", square(4.9, -0.1, 5.1, 0.1), 10, 40, 5));
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  EXPECT_NEAR(r.jobs[0].x, 5, 1e-9);
  // At the job for its whole duration, away while the obstacle passes, and parked for good.
  EXPECT_NEAR(s.trajectory("n").position_at(r.jobs[0].start + 2.5).x(), 5, 1e-9);
  const Point at_crossing = s.trajectory("n").position_at(110);
  EXPECT_GT(std::hypot(at_crossing.x() - 5, at_crossing.y()), 0.7);
  EXPECT_LT(s.trajectory("n").end_time(), 110);
  const auto violations = clearance_violations(s, "n", crossing, 0.5);
  EXPECT_TRUE(violations.empty()) << violations.front();
}

// The periodic failure case of the benchmark: an obstacle parks on the place only after the last
// repetition. With the old rule the set failed at its first job already.
TEST(Scheduler, PeriodicSetSucceedsWhenTheObstacleComesAfterItsLastRepetition) {
  World w;
  const MovingObstacle parked{square(-2, -2, 2, 2), Trajectory({{5, 0, 75}, {5, 0, 90}})};
  w.dynamic_obstacles.push_back(parked);
  Scheduler s(std::move(w), {});
  s.add_node({"n", 0.2, 1, 0, 0, 0, 0});
  const auto r = s.schedule(PeriodicSpec{{"P1", "P2", "P3"}, square(4, -1, 6, 1), true, 10, 20, 5});
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  const auto violations = clearance_violations(s, "n", parked, 2);
  EXPECT_TRUE(violations.empty()) << violations.front();
  // An obstacle on the place during the last period still makes the set fail, atomically.
  World w2;
  w2.dynamic_obstacles.push_back({square(-2, -2, 2, 2), Trajectory({{5, 0, 45}, {5, 0, 100}})});
  Scheduler s2(std::move(w2), {});
  s2.add_node({"n", 0.2, 1, 0, 0, 0, 0});
  EXPECT_FALSE(
      s2.schedule(PeriodicSpec{{"P1", "P2", "P3"}, square(4, -1, 6, 1), true, 10, 20, 5}).ok);
  EXPECT_TRUE(s2.jobs("n", false).empty());
}

// A node added where something will pass later steps aside instead of being refused.
TEST(Scheduler, NodeAddedInTheWayOfALaterObstacleStepsAside) {
  World w;
  const MovingObstacle crossing{square(-0.5, -0.5, 0.5, 0.5),
                                Trajectory({{0, -10, 10}, {0, 10, 30}})};
  w.dynamic_obstacles.push_back(crossing);
  Scheduler s(std::move(w), {});
  s.add_node({"n", 0.2, 1, 0, 0, 0, 0});
  EXPECT_GT(s.trajectory("n").points().size(), 1u);
  const auto violations = clearance_violations(s, "n", crossing, 0.5);
  EXPECT_TRUE(violations.empty()) << violations.front();
}

}  // namespace
}  // namespace oscar::swarm
