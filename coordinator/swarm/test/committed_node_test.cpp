// A node added with the trajectory and jobs it has committed already (a coordinator that
// restarted takes over its robots' plans): Scheduler::add_node(spec, committed, jobs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "expect_error.hpp"
#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm {
namespace {

using test::expect_error;

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

Polygon around(double x, double y) { return square(x - 0.05, y - 0.05, x + 0.05, y + 0.05); }

// n1 committed before: from (5, 0) at 0 along y = 0 to (20, 0) at 15 (1 m/s), where it works J
// in [15, 20] (window [0, 40]). It is taken over at t = 2, at (7, 0).
const NodeSpec kN1{"n1", 0.5, 1, 7, 0, 2, 0};
const Trajectory kDrive({{5, 0, 0}, {20, 0, 15}});
Job job_j() { return {"J", "n1", 20, 0, 15, 5, JobSpec{"J", around(20, 0), 0, 40, 5}}; }

// The smallest distance between two trajectories over [t0, t1], sampled every 10 ms.
double closest(const Trajectory& a, const Trajectory& b, double t0, double t1) {
  double d = 1e9;
  for (double t = t0; t <= t1; t += 0.01) {
    d = std::min(d, distance(a.position_at(t), b.position_at(t)));
  }
  return d;
}

TEST(CommittedNode, TakesTheTrajectoryAndJobsAsTheCommittedSchedule) {
  Scheduler s({}, {.present = 2});
  s.add_node(kN1, kDrive, {job_j()});
  ASSERT_EQ(s.trajectory("n1").points().size(), 2u);
  EXPECT_DOUBLE_EQ(s.trajectory("n1").position_at(10).x(), 15);
  EXPECT_DOUBLE_EQ(s.trajectory("n1", false).position_at(10).x(), 15);
  ASSERT_EQ(s.jobs("n1").size(), 1u);
  EXPECT_EQ(s.jobs("n1")[0].id, "J");
  EXPECT_EQ(s.jobs("n1", false).size(), 1u);
  EXPECT_TRUE(s.open_transactions().empty());
  // A committed job like any other: a breakdown gives it back with its spec, to be placed again.
  const auto lost = s.break_down("n1", 3, Point(8, 0));
  ASSERT_EQ(lost.size(), 1u);
  EXPECT_EQ(lost[0].id, "J");
  EXPECT_DOUBLE_EQ(lost[0].spec.latest_finish, 40);
}

// The defect this overload mends: a node added idle where it is now is no obstacle where it
// drives, so another node is planned across its path; added with its committed trajectory, the
// other node keeps its distance.
TEST(CommittedNode, OtherNodesAvoidItsCommittedTrajectory) {
  // n2 at (10, -3) works K at (10, 5) starting in [10, 14]: leaving at once at full speed, it
  // crosses y = 0 at t = 5, when n1 drives past (10, 0).
  const NodeSpec n2{"n2", 0.5, 1, 10, -3, 2, 0};
  const JobSpec k{"K", around(10, 5), 10, 16, 2};
  {
    Scheduler idle({}, {.present = 2});
    idle.add_node(n2);
    idle.add_node(kN1);  // as if it stood at (7, 0): what a restarted coordinator did
    // n1 would be asked first and refuse (it is not where the plan starts): planned without it.
    idle.set_excluded({"n1"});
    const auto r = idle.schedule(k);
    ASSERT_TRUE(r.ok) << r.reason;
    ASSERT_EQ(r.jobs[0].node, "n2");
    EXPECT_LT(closest(idle.trajectory("n2", false), kDrive, 2, 20), 1.0);
  }
  Scheduler s({}, {.present = 2});
  s.add_node(n2);
  s.add_node(kN1, kDrive, {job_j()});
  const auto r = s.schedule(k);
  ASSERT_TRUE(r.ok) << r.reason;
  ASSERT_EQ(r.jobs[0].node, "n2");
  s.commit(r.transaction);
  EXPECT_GE(closest(s.trajectory("n2"), s.trajectory("n1"), 2, 30), 1.0 - 1e-6);
  EXPECT_GE(r.jobs[0].start, 10);
  EXPECT_LE(r.jobs[0].end(), 16 + 1e-9);
}

TEST(CommittedNode, NewJobsOfTheNodeGoIntoItsPausesAroundItsCommittedJobs) {
  Scheduler s({}, {.present = 2});
  s.add_node(kN1, kDrive, {job_j()});
  // From (7, 0) at 2 to (20, 2) and back to J's place by 15 does not fit: K2 comes after J.
  const auto r = s.schedule(JobSpec{"K2", around(20, 2), 0, 40, 3});
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  const auto& jobs = s.jobs("n1");
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs[0].id, "J");
  EXPECT_DOUBLE_EQ(jobs[0].start, 15);
  EXPECT_EQ(jobs[1].id, "K2");
  EXPECT_GE(jobs[1].start, 20 + 2 - 1e-9);  // J's end, then 2 m at 1 m/s
  // The committed drive and job are kept.
  EXPECT_NEAR(s.trajectory("n1").position_at(10).x(), 15, 1e-9);
  EXPECT_NEAR(s.trajectory("n1").position_at(17).x(), 20, 1e-9);
}

TEST(CommittedNode, ACommittedPlanThatDoesNotFitIsRefusedWithTheRule) {
  auto add = [](NodeSpec spec, Trajectory t, std::vector<Job> jobs) {
    return [=] {
      Scheduler s({}, {.present = 2});
      s.add_node({"other", 0.5, 1, 0, 10, 2, 0});
      const auto r = s.schedule(JobSpec{"X", around(0, 12), 0, 40, 5});
      EXPECT_TRUE(r.ok) << r.reason;
      s.commit(r.transaction);
      s.add_node(spec, t, jobs);
    };
  };
  expect_error(add(kN1, Trajectory(), {}), "node 'n1': its committed trajectory is empty");
  expect_error(add(kN1, Trajectory({{7, 0, 3}, {20, 0, 16}}), {}),
               "node 'n1': its committed trajectory starts at 3, after the node's time 2");
  expect_error(add({"n1", 0.5, 1, 7, 1, 2, 0}, kDrive, {}),
               "node 'n1': its committed trajectory has it at (7.000, 0.000) at 2, not where it "
               "is, (7.000, 1.000)");
  Job off = job_j();
  off.y = 1;
  expect_error(add(kN1, kDrive, {off}),
               "node 'n1': committed job 'J': the committed trajectory has the node at (20.000, "
               "0.000) at 15, not at the job's place (20.000, 1.000)");
  Job early = job_j();
  early.start = 10;
  early.duration = 10;
  expect_error(add(kN1, kDrive, {early}),
               "committed job 'J': the committed trajectory has the "
               "node at (15.000, 0.000) at 10");
  Job late = job_j();
  late.spec.latest_finish = 19;
  expect_error(add(kN1, kDrive, {late}),
               "node 'n1': committed job 'J': [15, 20] lies outside its window [0, 19]");
  Job done = job_j();
  done.x = 7;
  done.start = 0;
  done.duration = 1;
  expect_error(add(kN1, kDrive, {done}),
               "committed job 'J': it ended at 1, before the node's "
               "time 2: only jobs not yet done are committed");
  Job second = job_j();
  second.id = second.spec.id = "J2";
  second.start = 17;
  expect_error(add(kN1, kDrive, {job_j(), second}),
               "committed job 'J2': it starts at 17, before job 'J' ends at 20");
  Job taken = job_j();
  taken.id = taken.spec.id = "X";
  expect_error(add(kN1, kDrive, {taken}), "job 'X': id is already scheduled");
  Job elsewhere = job_j();
  elsewhere.node = "n7";
  expect_error(add(kN1, kDrive, {elsewhere}), "committed job 'J' is scheduled on node 'n7'");
  Job unnamed = job_j();
  unnamed.spec.id = "Q";
  expect_error(add(kN1, kDrive, {unnamed}), "committed job 'J': its spec names job 'Q'");
  expect_error(add({"other", 0.5, 1, 7, 0, 2, 0}, kDrive, {}), "duplicate node id");
  // A refused node is not added.
  Scheduler s({}, {.present = 2});
  EXPECT_THROW(s.add_node(kN1, kDrive, {off}), std::invalid_argument);
  EXPECT_TRUE(s.node_ids().empty());
}

TEST(CommittedNode, WhereItIsMustBeFreeOfStaticObstacles) {
  World w;
  w.static_obstacles.push_back(square(6, -1, 8, 1));
  Scheduler s(w, {.present = 2});
  expect_error([&] { s.add_node(kN1, kDrive, {job_j()}); },
               "node 'n1': where it is lies within radius of a static obstacle");
}

}  // namespace
}  // namespace oscar::swarm
