// Regressions of the planner review: transactions keep disjoint sections, sets stay sets after
// scheduling, nodes are removed only when done, locations are sampled from the free area (A.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "expect_error.hpp"
#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm {
namespace {

using test::expect_error;

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

bool near(const Point& p, double x, double y) { return std::hypot(p.x() - x, p.y() - y) < 1e-6; }

// One node with committed jobs J1 at (3,0) from 5 and J2 at (3,0) from 40; job X at (-3,0) in
// the pause between them stays open (transaction A); then a periodic set places P0 before J1 and
// P1 after J2 (transaction B): B changes two sections with A's open section between them.
struct Interleaved {
  Scheduler s{{}, {}};
  ScheduleResult a, b;
  Interleaved() {
    s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
    for (const auto& j : {JobSpec{"J1", square(2.9, -0.1, 3.1, 0.1), 5, 15, 2},
                          JobSpec{"J2", square(2.9, -0.1, 3.1, 0.1), 40, 50, 2}}) {
      const auto r = s.schedule(j);
      EXPECT_TRUE(r.ok) << r.reason;
      s.commit(r.transaction);
    }
    a = s.schedule(JobSpec{"X", square(-3.1, -0.1, -2.9, 0.1), 20, 30, 2});
    EXPECT_TRUE(a.ok) << a.reason;
    b = s.schedule(PeriodicSpec{{"P0", "P1"}, square(0.9, -0.1, 1.1, 0.1), true, 0, 50, 1});
    EXPECT_TRUE(b.ok) << b.reason;
    EXPECT_LT(b.jobs[0].start, 5);   // before J1
    EXPECT_GT(b.jobs[1].start, 42);  // after J2
  }
  Point working_at(double t) const { return s.trajectory("n1", false).position_at(t); }
  Point committed_at(double t) const { return s.trajectory("n1", true).position_at(t); }
};

TEST(Transactions, AbortingASetAroundAnotherOpenJobKeepsThatJobsDetour) {
  Interleaved w;
  const double x_start = w.a.jobs[0].start;
  ASSERT_TRUE(near(w.working_at(x_start + 1), -3, 0));
  w.s.abort(w.b.transaction);
  EXPECT_TRUE(near(w.working_at(x_start + 1), -3, 0)) << "the set's abort undid X's detour";
  w.s.commit(w.a.transaction);
  EXPECT_TRUE(near(w.committed_at(x_start + 1), -3, 0)) << "X committed without going there";
  ASSERT_EQ(w.s.jobs("n1").size(), 3u);
}

TEST(Transactions, CommittingASetAroundAnotherOpenJobLeavesThatDetourUncommitted) {
  Interleaved w;
  const double x_start = w.a.jobs[0].start;
  w.s.commit(w.b.transaction);
  EXPECT_FALSE(near(w.committed_at(x_start + 1), -3, 0)) << "X's open detour was committed";
  EXPECT_TRUE(near(w.committed_at(w.b.jobs[0].start), 1, 0));
  EXPECT_TRUE(near(w.committed_at(w.b.jobs[1].start), 1, 0));
  w.s.abort(w.a.transaction);
  EXPECT_TRUE(near(w.working_at(x_start + 1), w.committed_at(x_start + 1).x(), 0));
  EXPECT_TRUE(near(w.working_at(w.b.jobs[1].start), 1, 0)) << "X's abort undid the set";
  EXPECT_EQ(w.s.jobs("n1", false).size(), 4u);
}

// Two nodes far apart, a periodic set whose repetitions go one to each.
Scheduler two_nodes() {
  Scheduler s({}, {});
  s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
  s.add_node({"n2", 0.1, 1, 0, 10, 0, 0});
  return s;
}

TEST(JobSets, MembersAreNotUnscheduledRemovedOrRescheduledAlone) {
  Scheduler s = two_nodes();
  const auto set = s.schedule(DependentSpec{
      {{"A", square(-1, -1, 1, 1), 10, 15, 5}, {"B", square(-1, 9, 1, 11), 30, 40, 5}},
      {{"B", {"A"}}}});
  ASSERT_TRUE(set.ok) << set.reason;
  s.commit(set.transaction);
  for (const auto& r : {s.unschedule("A"), s.remove_job("A"),
                        s.reschedule({"A", square(-1, -1, 1, 1), 20, 29, 5})}) {
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.reason.find("belongs to the dependent set A, B"), std::string::npos) << r.reason;
  }
  EXPECT_TRUE(s.open_transactions().empty());
  EXPECT_EQ(s.jobs("n1").size() + s.jobs("n2").size(), 2u);
  const auto gone = s.unschedule_set("B");
  ASSERT_TRUE(gone.ok) << gone.reason;
  s.commit(gone.transaction);
  EXPECT_TRUE(s.jobs("n1").empty());
  EXPECT_TRUE(s.jobs("n2").empty());
  // Membership ends with the jobs: a new single job may take a former member's id.
  const auto single = s.schedule(JobSpec{"A", square(-1, -1, 1, 1), 10, 15, 5});
  ASSERT_TRUE(single.ok) << single.reason;
  s.commit(single.transaction);
  EXPECT_TRUE(s.unschedule("A").ok);
  expect_error([&] { s.unschedule_set("nope"); }, "unknown job id 'nope'");
}

TEST(JobSets, UnschedulingASetKeepsWhatHasStarted) {
  Scheduler s = two_nodes();
  const auto set =
      s.schedule(PeriodicSpec{{"P0", "P1", "P2"}, square(-1, -1, 1, 1), true, 0, 20, 2});
  ASSERT_TRUE(set.ok) << set.reason;
  s.commit(set.transaction);
  s.set_present(set.jobs[1].start + 0.5);  // P0 done, P1 under way
  const auto rest = s.unschedule_set("P0");
  ASSERT_TRUE(rest.ok) << rest.reason;
  s.commit(rest.transaction);
  std::vector<std::string> left;
  for (const auto& n : {"n1", "n2"}) {
    for (const auto& j : s.jobs(n)) left.push_back(j.id);
  }
  EXPECT_EQ(left, (std::vector<std::string>{"P0", "P1"}));
}

TEST(JobSets, AnAtomicTransactionOverSeveralNodesFinishesOnlyAsAWhole) {
  Scheduler s = two_nodes();
  const auto set = s.schedule(DependentSpec{
      {{"A", square(-1, -1, 1, 1), 10, 15, 5}, {"B", square(-1, 9, 1, 11), 10, 15, 5}}, {}});
  ASSERT_TRUE(set.ok) << set.reason;
  ASSERT_NE(set.jobs[0].node, set.jobs[1].node);
  expect_error([&] { s.commit(set.transaction, "n1"); },
               "(dependent set A, B) changes 2 nodes and commits only as a whole");
  expect_error([&] { s.abort(set.transaction, "n2"); }, "aborts only as a whole");
  s.abort(set.transaction);
  EXPECT_TRUE(s.jobs("n1", false).empty());
  EXPECT_TRUE(s.jobs("n2", false).empty());
  // An aborted set leaves no membership behind either.
  const auto single = s.schedule(JobSpec{"A", square(-1, -1, 1, 1), 10, 15, 5});
  ASSERT_TRUE(single.ok);
  s.commit(single.transaction);
  EXPECT_TRUE(s.unschedule("A").ok);
}

TEST(Nodes, ANodeIsRemovedOnlyWhenItsJobsAreDone) {
  Scheduler s = two_nodes();
  const auto r = s.schedule(JobSpec{"A", square(-1, -1, 1, 1), 10, 15, 5});
  ASSERT_TRUE(r.ok);
  const std::string node = r.jobs[0].node;
  expect_error([&] { s.remove_node(node); }, "open transaction");
  s.commit(r.transaction);
  expect_error([&] { s.remove_node(node); }, "job 'A' ends at 15");
  expect_error([&] { s.remove_node("n9"); }, "unknown node id 'n9'");
  s.set_present(15);
  s.remove_node(node);
  EXPECT_EQ(s.node_ids().size(), 1u);
  // §4.1: a removed node vanishes, it is no obstacle: the other node may drive through its place.
  const std::string other = node == "n1" ? "n2" : "n1";
  const Point gone_at = node == "n1" ? Point(0, 0) : Point(0, 10);
  const auto through = s.schedule(JobSpec{
      "B", square(gone_at.x() - 0.2, gone_at.y() - 0.2, gone_at.x() + 0.2, gone_at.y() + 0.2), 16,
      100, 1});
  ASSERT_TRUE(through.ok) << through.reason;
  EXPECT_EQ(through.jobs[0].node, other);
}

TEST(Nodes, ABrokenDownNodeGivesUpItsJobsAndStaysAnObstacle) {
  Scheduler s = two_nodes();
  const auto r = s.schedule(JobSpec{"A", square(-1, -1, 1, 1), 20, 40, 5});
  ASSERT_TRUE(r.ok);
  const std::string node = r.jobs[0].node;
  expect_error([&] { s.break_down(node, 1, Point(0, 0)); }, "open transaction");
  s.commit(r.transaction);
  const Point where = s.trajectory(node).position_at(2);
  const auto lost = s.break_down(node, 2, where);
  ASSERT_EQ(lost.size(), 1u);
  EXPECT_EQ(lost[0].id, "A");
  EXPECT_TRUE(s.broken_down(node));
  EXPECT_TRUE(s.jobs(node).empty());
  EXPECT_TRUE(near(s.trajectory(node).position_at(1000), where.x(), where.y()));
  // The other node takes the job, next to the broken one, not on top of it.
  const auto again = s.schedule(lost[0].spec);
  ASSERT_TRUE(again.ok) << again.reason;
  EXPECT_NE(again.jobs[0].node, node);
  EXPECT_GT(distance(again.jobs[0].location(), where), 0.2 - 1e-9);
  const auto on_top = s.schedule(
      JobSpec{"B", square(where.x() - 0.01, where.y() - 0.01, where.x() + 0.01, where.y() + 0.01),
              50, 100, 1});
  EXPECT_FALSE(on_top.ok);
  expect_error([&] { s.break_down(node, 3, where); }, "broke down already");
}

// A broken-down node's set members are placed again within their set (schedule_lost). Job A
// (20 s, from 10) at (2, 0) goes to n1 next to it and B (5 s, waits for A) next to n2 at
// (0, 10); n3 at (5, 0) is busy with X until 45, n4 at (0, y4) is free. n1 breaks down at 1,
// before A starts.
struct BrokenSetMember {
  Scheduler s{{}, {}};
  ScheduleResult set;
  std::vector<Job> lost;
  explicit BrokenSetMember(double y4) {
    s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
    s.add_node({"n2", 0.1, 1, 0, 10, 0, 0});
    s.add_node({"n3", 0.1, 1, 5, 0, 0, 0});
    s.add_node({"n4", 0.1, 1, 0, y4, 0, 0});
    const auto x = s.schedule(JobSpec{"X", square(4.9, -0.1, 5.1, 0.1), 0, 45, 45});
    EXPECT_TRUE(x.ok) << x.reason;
    s.commit(x.transaction);
    set = s.schedule(DependentSpec{{{"A", square(1.9, -0.1, 2.1, 0.1), 10, 100, 20},
                                    {"B", square(0.5, 9.5, 1.5, 10.5), 0, 100, 5}},
                                   {{"B", {"A"}}}});
    EXPECT_TRUE(set.ok) << set.reason;
    EXPECT_EQ(set.jobs[0].node, "n1");
    EXPECT_EQ(set.jobs[1].node, "n2");
    s.commit(set.transaction);
    s.set_present(1);
    lost = s.break_down("n1", 1, s.trajectory("n1").position_at(1));
    EXPECT_EQ(lost.size(), 1u);
  }
  std::vector<std::string> job_ids() const {
    std::vector<std::string> ids;
    for (const auto& n : s.node_ids()) {
      for (const auto& j : s.jobs(n)) ids.push_back(j.id);
    }
    std::sort(ids.begin(), ids.end());
    return ids;
  }
};

TEST(JobSets, ABrokenDownNodesDependentMemberIsPlacedAgainBeforeWhatWaitsForIt) {
  BrokenSetMember w(-8);
  const double b_start = w.set.jobs[1].start;
  // A stays in its set, lost. Alone in its window it would take the least detour, n3 after X,
  // and end after B has started; within its set it must end by B's start: n4 from afar.
  EXPECT_EQ(w.s.set_name("A"), "dependent set A, B");
  expect_error(
      [&] {
        w.s.schedule(JobSpec{"A", square(-1, -1, 1, 1), 50, 100, 1});
      },
      "waits to be placed again");
  const auto first = w.s.schedule_lost("A");
  ASSERT_TRUE(first.ok) << first.reason;
  w.s.abort(first.transaction);  // e.g. a robot refused: A is still lost and goes again
  const auto again = w.s.schedule_lost("B");
  ASSERT_TRUE(again.ok) << again.reason;
  ASSERT_EQ(again.jobs.size(), 1u);
  const Job& a = again.jobs[0];
  EXPECT_EQ(a.id, "A");
  EXPECT_EQ(a.node, "n4");
  EXPECT_LE(a.end(), b_start + 1e-9) << "A ends after B, which waits for it, has started";
  EXPECT_EQ(a.spec.latest_finish, w.lost[0].spec.latest_finish);  // the window it was placed in
  w.s.commit(again.transaction);
  expect_error([&] { w.s.schedule_lost("A"); }, "has no lost member to place again");
  // A is a member as before: not unscheduled alone, but with its set.
  const auto alone = w.s.unschedule("A");
  EXPECT_FALSE(alone.ok);
  EXPECT_NE(alone.reason.find("belongs to the dependent set A, B"), std::string::npos)
      << alone.reason;
  const auto gone = w.s.unschedule_set("A");
  ASSERT_TRUE(gone.ok) << gone.reason;
  w.s.commit(gone.transaction);
  EXPECT_EQ(w.job_ids(), std::vector<std::string>{"X"});
}

TEST(JobSets, ASetThatCannotBeWholeAgainStaysAsItWasUntilItIsGivenUp) {
  // n4 is 20 m out: A must end by B's start, and only n1 could have made it in time.
  BrokenSetMember w(-20);
  const auto again = w.s.schedule_lost("A");
  EXPECT_FALSE(again.ok);
  EXPECT_EQ(again.reason.rfind("job 'A': ", 0), 0u) << again.reason;
  EXPECT_TRUE(w.s.open_transactions().empty());
  EXPECT_EQ(w.job_ids(), (std::vector<std::string>{"B", "X"}));
  EXPECT_EQ(w.s.set_name("A"), "dependent set A, B");
  // Given up: B leaves n2's schedule and A its set; both ids are free again.
  const auto gone = w.s.unschedule_set("A");
  ASSERT_TRUE(gone.ok) << gone.reason;
  EXPECT_EQ(w.s.set_name("A"), "dependent set A, B") << "given up only on commit";
  w.s.commit(gone.transaction);
  EXPECT_EQ(w.job_ids(), std::vector<std::string>{"X"});
  EXPECT_EQ(w.s.set_name("A"), "");
  EXPECT_EQ(w.s.set_name("B"), "");
  const auto single = w.s.schedule(JobSpec{"A", square(-1, 2, 1, 4), 50, 100, 1});
  EXPECT_TRUE(single.ok) << single.reason;
}

TEST(JobSets, ABrokenDownNodesPeriodicMembersArePlacedAgainInTheirRepetitionsAtTheSetsPlace) {
  Scheduler s = two_nodes();
  const auto set =
      s.schedule(PeriodicSpec{{"P0", "P1", "P2"}, square(2, -1, 4, 1), true, 0, 20, 2});
  ASSERT_TRUE(set.ok) << set.reason;
  s.commit(set.transaction);
  const std::string node = set.jobs[0].node;
  const auto lost = s.break_down(node, 1, s.trajectory(node).position_at(1));
  ASSERT_FALSE(lost.empty());
  const auto again = s.schedule_lost(lost[0].id);
  ASSERT_TRUE(again.ok) << again.reason;
  ASSERT_EQ(again.jobs.size(), lost.size());
  for (const auto& j : again.jobs) {
    const double i = j.id == "P0" ? 0 : j.id == "P1" ? 1 : 2;
    EXPECT_NE(j.node, node);
    EXPECT_TRUE(near(j.location(), set.jobs[0].x, set.jobs[0].y)) << j.id << " not at the set's";
    EXPECT_GE(j.start, i * 20 - 1e-9) << j.id;
    EXPECT_LE(j.end(), (i + 1) * 20 + 1e-9) << j.id;
  }
  s.commit(again.transaction);
  const auto alone = s.unschedule(lost[0].id);
  EXPECT_FALSE(alone.ok);
  EXPECT_NE(alone.reason.find("belongs to the periodic set P0, P1, P2"), std::string::npos)
      << alone.reason;
}

TEST(Transactions, ChangesNameTheSectionsAndJobsPerNode) {
  Scheduler s = two_nodes();
  const auto r = s.schedule(JobSpec{"A", square(-1, -1, 1, 1), 20, 40, 5});
  ASSERT_TRUE(r.ok);
  const auto changes = s.changes(r.transaction);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].node, r.jobs[0].node);
  ASSERT_EQ(changes[0].sections.size(), 1u);
  EXPECT_LE(changes[0].sections[0].first, r.jobs[0].start);
  ASSERT_EQ(changes[0].added.size(), 1u);
  EXPECT_EQ(changes[0].added[0].id, "A");
  EXPECT_TRUE(changes[0].removed.empty());
  s.commit(r.transaction);
  expect_error([&] { s.changes(r.transaction); }, "unknown or finished transaction");
}

TEST(Nodes, ForgettingThePastKeepsWhereNodesAreAndWhatIsToCome) {
  Scheduler s = two_nodes();
  for (const auto& j : {JobSpec{"A", square(2, -1, 4, 1), 5, 10, 2},
                        JobSpec{"B", square(2, 9, 4, 11), 50, 60, 2}}) {
    const auto r = s.schedule(j);
    ASSERT_TRUE(r.ok) << r.reason;
    s.commit(r.transaction);
  }
  s.set_present(30);
  const std::string a_node = s.jobs("n1").empty() ? "n2" : "n1";
  const Point at_20 = s.trajectory(a_node).position_at(20);
  const Point b_at_55 = s.trajectory("n2").position_at(55);
  s.forget_before(20);
  EXPECT_GE(s.trajectory(a_node).start_time(), 20);
  EXPECT_TRUE(near(s.trajectory(a_node).position_at(20), at_20.x(), at_20.y()));
  EXPECT_TRUE(near(s.trajectory("n2").position_at(55), b_at_55.x(), b_at_55.y()));
  std::vector<std::string> left;
  for (const auto& n : {"n1", "n2"}) {
    for (const auto& j : s.jobs(n)) left.push_back(j.id);
  }
  EXPECT_EQ(left, std::vector<std::string>{"B"});
  // Planning goes on as before: a new job, and the old id is free again.
  const auto again = s.schedule(JobSpec{"A", square(2, -1, 4, 1), 35, 45, 2});
  EXPECT_TRUE(again.ok) << again.reason;
  expect_error([&] { s.forget_before(31); }, "lies after the present");
}

TEST(LocationSampling, SamplesTheAreaMinusStaticObstacles) {
  // The area's centroid lies in an obstacle; with one sample (A.1: the free area's first sample),
  // the job still finds a place.
  World world;
  world.static_obstacles.push_back(square(1, 1, 3, 3));
  Scheduler s(world, {.location_samples = 1});
  s.add_node({"n1", 0.1, 1, -2, -2, 0, 0});
  const auto r = s.schedule(JobSpec{"A", square(0, 0, 4, 4), 0, 100, 1});
  ASSERT_TRUE(r.ok) << r.reason;
  const Point at = r.jobs[0].location();
  EXPECT_FALSE(strictly_inside(at, world.static_obstacles[0]));
  EXPECT_TRUE(strictly_inside(at, square(0, 0, 4, 4)));
  const auto walled = s.schedule(JobSpec{"B", square(1.5, 1.5, 2.5, 2.5), 0, 100, 1});
  EXPECT_FALSE(walled.ok);
  EXPECT_NE(walled.reason.find("wholly within static obstacles"), std::string::npos)
      << walled.reason;
}

TEST(LocationSampling, SamplesSpreadOverTheAreaAndRepeat) {
  // An L-shaped free area whose first sample (top strip) is too far for the job's window: a later
  // sample, in a rectangle of the split, lies in the right strip near the node.
  auto place = [](int samples) {
    World world;
    world.static_obstacles.push_back(square(0, 0, 9, 9));  // leaves an L of width 1
    Scheduler s(world, {.location_samples = samples});
    s.add_node({"n1", 0.1, 1, 9.5, -1, 0, 0});
    const auto r = s.schedule(JobSpec{"A", square(0, 0, 10, 10), 0, 8, 1});
    return r.ok ? std::optional<Point>(r.jobs[0].location()) : std::nullopt;
  };
  const auto a = place(20), b = place(20);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(near(*a, b->x(), b->y())) << "sampling is deterministic";
  EXPECT_GT(a->x(), 9);
}

}  // namespace
}  // namespace oscar::swarm
