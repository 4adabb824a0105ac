#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "expect_error.hpp"
#include "oscar/swarm/dependency_windows.hpp"
#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm {
namespace {

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

// Table 4.1 (t_max there is the latest start: latest_finish = t_max + d).
std::vector<JobSpec> table_4_1() {
  return {{"A", square(1, 1, 2, 2), 20, 75, 5},
          {"B", square(3, 1, 4, 2), 0, 105, 5},
          {"C", square(2, 3, 3, 4), 0, 110, 10}};
}
const std::map<std::string, std::vector<std::string>> kDepends{{"C", {"A", "B"}}};

TEST(DependencyWindows, Table41NormalisesToTable42) {
  const auto w = implicit_windows(table_4_1(), kDepends, 0);
  EXPECT_DOUBLE_EQ(w.at("A").earliest_start, 20);
  EXPECT_DOUBLE_EQ(w.at("A").latest_start, 70);
  EXPECT_DOUBLE_EQ(w.at("B").earliest_start, 0);
  EXPECT_DOUBLE_EQ(w.at("B").latest_start, 95);
  EXPECT_DOUBLE_EQ(w.at("C").earliest_start, 25);
  EXPECT_DOUBLE_EQ(w.at("C").latest_start, 100);
}

TEST(DependencyWindows, MarginWidensTheGapBetweenDependentJobs) {
  const auto w = implicit_windows(table_4_1(), kDepends, 3);  // eq. 4.10/4.11
  EXPECT_DOUBLE_EQ(w.at("C").earliest_start, 28);
  EXPECT_DOUBLE_EQ(w.at("B").latest_start, 92);
}

TEST(DependencyWindows, CyclesAndUnknownIdsAreErrors) {
  auto jobs = table_4_1();
  try {
    implicit_windows(jobs, {{"C", {"A"}}, {"A", {"C"}}}, 0);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cycle"), std::string::npos);
  }
  try {
    implicit_windows(jobs, {{"C", {"Z"}}}, 0);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown job id 'Z'"), std::string::npos);
  }
}

TEST(Scheduler, DependentJobsOfTable41AreScheduledAThenBThenC) {
  Scheduler s({}, {});
  s.add_node({"n1", 0.1, 0.5, 0, 0, 0, 0});
  const auto r = s.schedule(DependentSpec{table_4_1(), kDepends});
  ASSERT_TRUE(r.ok) << r.reason;
  ASSERT_EQ(r.jobs.size(), 3u);
  EXPECT_EQ(r.jobs[0].id, "A");
  EXPECT_EQ(r.jobs[1].id, "B");
  EXPECT_EQ(r.jobs[2].id, "C");
  EXPECT_GE(r.jobs[2].start, r.jobs[0].end());
  EXPECT_GE(r.jobs[2].start, r.jobs[1].end());
  EXPECT_GE(r.jobs[0].start, 20);
}

TEST(Scheduler, PeriodicJobsAtTheSameLocationOnePerPeriod) {
  Scheduler s({}, {});
  s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
  const auto r = s.schedule(PeriodicSpec{{"P1", "P2", "P3"}, square(4, -1, 6, 1), true, 10, 20, 5});
  ASSERT_TRUE(r.ok) << r.reason;
  ASSERT_EQ(r.jobs.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(r.jobs[i].start, 10 + 20 * i);
    EXPECT_LE(r.jobs[i].end(), 10 + 20 * (i + 1));
    EXPECT_DOUBLE_EQ(r.jobs[i].x, r.jobs[0].x);
    EXPECT_DOUBLE_EQ(r.jobs[i].y, r.jobs[0].y);
  }
}

TEST(Scheduler, IncompletePeriodicOrDependentSetLeavesTheScheduleUnchanged) {
  World w;
  // Something parks on the job area from t = 25 on.
  w.dynamic_obstacles.push_back({square(-2, -2, 2, 2), Trajectory({{5, 0, 25}, {5, 0, 100}})});
  Scheduler s(std::move(w), {});
  s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
  const auto before = s.trajectory("n1", false).points().size();
  const auto p = s.schedule(PeriodicSpec{{"P1", "P2", "P3"}, square(4, -1, 6, 1), false, 0, 10, 5});
  EXPECT_FALSE(p.ok);
  EXPECT_FALSE(p.reason.empty());
  auto jobs = table_4_1();
  jobs[2].area = square(4, -1, 6, 1);  // C needs the blocked area after A and B
  jobs[2].latest_finish = 40;
  jobs[2].earliest_start = 0;
  const auto d = s.schedule(DependentSpec{jobs, kDepends});
  EXPECT_FALSE(d.ok);
  EXPECT_TRUE(s.jobs("n1", false).empty());
  EXPECT_TRUE(s.jobs("n1", true).empty());
  EXPECT_EQ(s.trajectory("n1", false).points().size(), before);
  EXPECT_TRUE(s.open_transactions().empty());
}

TEST(Transactions, OpenAlternativeTrajectoriesAreObstaclesForOthers) {
  Scheduler s({}, {});
  s.add_node({"n1", 0.5, 1, 5, 0, 0, 0});  // idles on the spot everyone wants
  s.add_node({"n2", 0.5, 1, 20, 0, 0, 0});
  // n1 leaves (5,0) in an open transaction; its committed trajectory still stays there.
  const auto away = s.schedule(JobSpec{"Away", square(-1, 9, 1, 11), 0, 100, 5});
  ASSERT_TRUE(away.ok);
  ASSERT_EQ(away.jobs[0].node, "n1");
  const JobSpec here{"Here", square(4.5, -0.5, 5.5, 0.5), 50, 100, 5};
  const auto blocked = s.schedule(here);
  EXPECT_FALSE(blocked.ok) << "n2 went where n1 may still be";
  s.commit(away.transaction);
  const auto ok = s.schedule(here);
  EXPECT_TRUE(ok.ok) << ok.reason;
}

TEST(Transactions, LockedSectionsRefuseForeignChanges) {
  Scheduler s({}, {});
  s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
  const auto first = s.schedule(JobSpec{"J1", square(4, -1, 6, 1), 10, 100, 5});
  ASSERT_TRUE(first.ok);
  // The only node's open-ended slot is locked by the open transaction of J1.
  const auto second = s.schedule(JobSpec{"J2", square(-6, -1, -4, 1), 50, 100, 5});
  EXPECT_FALSE(second.ok);
  const auto removal = s.unschedule("J1");
  EXPECT_FALSE(removal.ok);
  EXPECT_NE(removal.reason.find("locked"), std::string::npos) << removal.reason;
  s.commit(first.transaction);
  EXPECT_TRUE(s.schedule(JobSpec{"J2", square(-6, -1, -4, 1), 50, 100, 5}).ok);
  // A job being removed by an open transaction cannot be removed again (§4.2.7).
  for (auto id : s.open_transactions()) s.commit(id);
  const auto removing = s.remove_job("J1");
  ASSERT_TRUE(removing.ok);
  const auto again = s.unschedule("J1");
  EXPECT_FALSE(again.ok);
  EXPECT_NE(again.reason.find("locked"), std::string::npos) << again.reason;
}

TEST(Transactions, CommitAndAbortPerNode) {
  Scheduler s({}, {});
  s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
  s.add_node({"n2", 0.1, 1, 0, 10, 0, 0});
  // Two single jobs far apart, one per node, each in a transaction of its own.
  const auto a = s.schedule(JobSpec{"A", square(-1, -1, 1, 1), 10, 15, 5});
  const auto b = s.schedule(JobSpec{"B", square(-1, 9, 1, 11), 10, 15, 5});
  ASSERT_TRUE(a.ok && b.ok);
  ASSERT_EQ(a.jobs[0].node, "n1");
  ASSERT_EQ(b.jobs[0].node, "n2");
  s.commit(a.transaction, "n2");  // a node the transaction does not change: nothing to do
  EXPECT_EQ(s.open_transactions().size(), 2u);
  s.commit(a.transaction, "n1");
  s.abort(b.transaction, "n2");
  EXPECT_TRUE(s.open_transactions().empty());
  EXPECT_EQ(s.jobs("n1").size(), 1u);
  EXPECT_TRUE(s.jobs("n2").empty());
  EXPECT_TRUE(s.jobs("n2", false).empty());
  try {
    s.commit(a.transaction);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown or finished transaction"), std::string::npos);
  }
}

using test::expect_error;

TEST(Scheduler, BadJobSetsAndWorldsGetClearErrors) {
  Scheduler s({}, {});
  s.add_node({"n1", 0.1, 1, 0, 0, 0, 0});
  const Polygon area = square(4, -1, 6, 1);
  expect_error(
      [&] {
        s.schedule(PeriodicSpec{{"P1", "P2"}, area, true, 0, 5, 10});
      },
      "0 < duration <= period");
  expect_error(
      [&] {
        s.schedule(PeriodicSpec{{"P1", "P2"}, area, true, 0, std::nan(""), 1});
      },
      "0 < duration <= period");
  expect_error(
      [&] {
        s.schedule(PeriodicSpec{{"P1", "P1"}, area, true, 0, 10, 1});
      },
      "duplicate id 'P1'");
  expect_error(
      [&] {
        s.schedule(PeriodicSpec{{}, area, true, 0, 10, 1});
      },
      "ids must not be empty");
  expect_error(
      [&] {
        s.schedule(DependentSpec{table_4_1(), {{"A", {"C"}}, {"C", {"A"}}}});
      },
      "cycle");
  expect_error(
      [&] {
        s.schedule(DependentSpec{table_4_1(), {{"C", {"Z"}}}});
      },
      "unknown job id 'Z'");
  EXPECT_TRUE(s.open_transactions().empty());
  World bad;
  bad.dynamic_obstacles.push_back({square(0, 0, 1, 1), Trajectory({{0, 0, 0}, {1, 1, 5e6}})});
  expect_error([&] { Scheduler(bad, {}); }, "world.dynamic[0] trajectory time");
  expect_error([&] { Trajectory({{0, 0, 0}, {1, 1, std::nan("")}}); }, "must be finite");
  expect_error([&] { Trajectory({{0, 0, 5}, {1, 1, 4}}); }, "must not decrease");
}

}  // namespace
}  // namespace oscar::swarm
