// The world changing while the swarm runs: Scheduler::change_world.
#include <gtest/gtest.h>

#include <algorithm>

#include "oscar/swarm/scheduler.hpp"
#include "schedule_checker.hpp"

namespace oscar::swarm {
namespace {

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

Polygon around(double x, double y) { return square(x - 0.05, y - 0.05, x + 0.05, y + 0.05); }

std::vector<check::Xyt> to_xyt(const Trajectory& t) {
  std::vector<check::Xyt> out;
  for (const auto& w : t.points()) out.push_back({w.x, w.y, w.t});
  return out;
}

std::vector<check::Xy> to_xy(const Polygon& p) {
  std::vector<check::Xy> out;
  for (const auto& v : vertices(p)) out.push_back({v.x(), v.y()});
  return out;
}

// The checker's words for what a node's committed trajectory does wrong in `world` (from t on).
std::vector<std::string> violations(const Scheduler& s, const std::string& id, const World& world,
                                    double from) {
  check::Checker c;
  check::Body node{id, {}, s.node(id).radius_m, {}, true, 0};
  for (const auto& w : s.trajectory(id).points()) {
    if (w.t >= from) node.trajectory.push_back({w.x, w.y, w.t});
  }
  const Point p = s.trajectory(id).position_at(from);
  node.trajectory.insert(node.trajectory.begin(), {p.x(), p.y(), from});
  std::vector<std::vector<check::Xy>> statics;
  for (const auto& o : world.static_obstacles) statics.push_back(to_xy(o));
  c.static_clearance(node, statics);
  for (const auto& o : world.dynamic_obstacles) {
    c.pair_clearance(node, {"moving", to_xy(o.shape), 0, to_xyt(o.trajectory), false, 0}, 200);
  }
  return c.violations;
}

// n1 stands at (0, 0) and works J at (20, 0), starting in [30, 60]: it drives along y = 0.
struct WorldChange : ::testing::Test {
  Scheduler s{{}, {.present = 0, .frozen_horizon = 1}};
  const JobSpec j{"J", around(20, 0), 30, 60, 5};
  void SetUp() override {
    s.add_node({"n1", 0.5, 1, 0, 0, 0, 0});
    const auto r = s.schedule(j);
    ASSERT_TRUE(r.ok) << r.reason;
    s.commit(r.transaction);
    s.set_present(2);
  }
  static World with_static(const Polygon& p) { return {{p}, {}}; }
};

TEST_F(WorldChange, ANodeDrivesAroundAnObstacleAddedAcrossItsWayAndKeepsItsJob) {
  const auto before = to_xyt(s.trajectory("n1"));
  ASSERT_FALSE(violations(s, "n1", with_static(square(9, -3, 11, 3)), 3).empty())
      << "the set-up must drive through the new obstacle";
  const auto change = s.change_world(with_static(square(9, -3, 11, 3)));
  ASSERT_TRUE(change.ok) << change.reason;
  ASSERT_NE(change.transaction, 0u);
  EXPECT_EQ(change.nodes, std::vector<std::string>{"n1"});
  EXPECT_TRUE(change.displaced.empty());
  s.commit(change.transaction);
  EXPECT_EQ(s.world().static_obstacles.size(), 1u);
  EXPECT_EQ(violations(s, "n1", s.world(), s.frozen_horizon_time() - 1),
            std::vector<std::string>{});
  ASSERT_EQ(s.jobs("n1").size(), 1u);
  EXPECT_DOUBLE_EQ(s.jobs("n1")[0].start, 30);
  EXPECT_DOUBLE_EQ(s.trajectory("n1").position_at(32).x(), 20);
  check::Checker c;
  c.unchanged_before("n1", before, to_xyt(s.trajectory("n1")), s.frozen_horizon_time());
  EXPECT_EQ(c.violations, std::vector<std::string>{});
}

TEST_F(WorldChange, AJobANodeCannotReachInTimeAnyMoreIsDisplacedAndCanBePlacedAgain) {
  // A wall from y = -40 to 40 at x = 10: the way round takes far longer than J's start allows.
  const auto change = s.change_world(with_static(square(9, -40, 11, 40)));
  ASSERT_TRUE(change.ok) << change.reason;
  ASSERT_EQ(change.displaced.size(), 1u);
  EXPECT_EQ(change.displaced[0].id, "J");
  EXPECT_TRUE(s.jobs("n1", false).empty());
  EXPECT_EQ(s.jobs("n1").size(), 1u) << "committed until the transaction commits";
  s.commit(change.transaction);
  EXPECT_TRUE(s.jobs("n1").empty());
  EXPECT_EQ(violations(s, "n1", s.world(), s.frozen_horizon_time()), std::vector<std::string>{});
  const auto again = s.schedule(change.displaced[0].spec);
  EXPECT_FALSE(again.ok) << "no node gets round the wall within J's window";
  EXPECT_NE(again.reason.find("'J'"), std::string::npos) << again.reason;
}

TEST_F(WorldChange, AnObstacleANodeRunsIntoBeforeTheFrozenHorizonIsRefused) {
  // n1 leaves (0, 0) at once: at 2 s it is within its frozen horizon there.
  const Point now = s.trajectory("n1").position_at(2.5);
  const auto change = s.change_world(with_static(square(now.x() - 1, -1, now.x() + 1, 1)));
  EXPECT_FALSE(change.ok);
  EXPECT_NE(change.reason.find("node 'n1' runs into the changed world"), std::string::npos)
      << change.reason;
  EXPECT_NE(change.reason.find("frozen horizon"), std::string::npos) << change.reason;
  EXPECT_TRUE(s.world().static_obstacles.empty()) << "the world stays as it was";
  EXPECT_TRUE(s.open_transactions().empty());
  EXPECT_EQ(s.jobs("n1", false).size(), 1u);
}

TEST_F(WorldChange, AnObstacleNobodyMeetsChangesOnlyTheWorld) {
  const auto before = to_xyt(s.trajectory("n1"));
  const auto change = s.change_world(with_static(square(5, 5, 8, 8)));
  ASSERT_TRUE(change.ok) << change.reason;
  EXPECT_EQ(change.transaction, 0u);
  EXPECT_TRUE(change.nodes.empty());
  EXPECT_TRUE(s.open_transactions().empty());
  EXPECT_EQ(s.world().static_obstacles.size(), 1u);
  EXPECT_EQ(to_xyt(s.trajectory("n1")), before);
  // New plans avoid it: a job behind it is reached around it.
  const auto r = s.schedule({"K", around(10, 10), 0, 200, 1});
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  EXPECT_EQ(violations(s, "n1", s.world(), 2), std::vector<std::string>{});
}

TEST_F(WorldChange, AMovingObstacleAddedAtRunTimeIsAvoided) {
  // A 2 m box crossing y = 0 at x = 10 from south to north, at about the time n1 passes there.
  const Trajectory crossing({{10, -20, 0}, {10, 20, 40}});
  const World world{{}, {{square(-1, -1, 1, 1), crossing}}};
  // (Where n1 drives now: the set-up must really meet it.)
  ASSERT_FALSE(violations(s, "n1", world, 3).empty()) << "the set-up must meet the obstacle";
  const auto change = s.change_world(world);
  ASSERT_TRUE(change.ok) << change.reason;
  ASSERT_NE(change.transaction, 0u);
  s.commit(change.transaction);
  EXPECT_EQ(violations(s, "n1", s.world(), s.frozen_horizon_time()), std::vector<std::string>{});
  ASSERT_EQ(s.jobs("n1").size(), 1u);
}

TEST_F(WorldChange, AbortedTheWorldStaysChangedAndTheNodesArePlannedAgainByTheSameChange) {
  const World world = with_static(square(9, -3, 11, 3));
  const auto first = s.change_world(world);
  ASSERT_TRUE(first.ok) << first.reason;
  s.abort(first.transaction);
  EXPECT_EQ(s.world().static_obstacles.size(), 1u);
  EXPECT_FALSE(violations(s, "n1", s.world(), 3).empty()) << "aborted: the old trajectory";
  s.set_present(3);
  const auto again = s.change_world(world);
  ASSERT_TRUE(again.ok) << again.reason;
  ASSERT_NE(again.transaction, 0u);
  s.commit(again.transaction);
  EXPECT_EQ(violations(s, "n1", s.world(), s.frozen_horizon_time()), std::vector<std::string>{});
}

TEST_F(WorldChange, IsRefusedWhileATransactionIsOpen) {
  const auto r = s.schedule({"K", around(-10, 0), 0, 200, 1});
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_THROW(s.change_world(with_static(square(5, 5, 8, 8))), std::invalid_argument);
  s.commit(r.transaction);
  EXPECT_TRUE(s.change_world(with_static(square(5, 5, 8, 8))).ok);
}

TEST(WorldChangeOfASet, ADisplacedMemberIsLostInItsSetAndPlacedAgainWithinIt) {
  Scheduler s{{}, {.present = 0, .frozen_horizon = 1}};
  s.add_node({"n1", 0.5, 1, 0, 0, 0, 0});
  s.add_node({"n2", 0.5, 1, 0, 10, 0, 0});
  // A then B; A on n1 (nearest), B after it.
  DependentSpec d{{{"A", around(20, 0), 20, 80, 2}, {"B", around(20, 10), 0, 120, 2}},
                  {{"B", {"A"}}}};
  const auto r = s.schedule(d);
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  s.set_present(2);
  const auto on_n1 = s.jobs("n1");
  ASSERT_FALSE(on_n1.empty());
  // A fence from y = -3 to 3 at x = 10 makes n1 late for whatever it does at (20, 0).
  const auto change = s.change_world({{square(9, -3, 11, 3)}, {}});
  ASSERT_TRUE(change.ok) << change.reason;
  ASSERT_EQ(change.displaced.size(), 1u);
  EXPECT_EQ(change.displaced[0].id, "A");
  EXPECT_FALSE(s.set_name("A").empty());
  if (change.transaction) s.commit(change.transaction);
  for (const auto& j : change.displaced) {
    EXPECT_EQ(s.set_name(j.id), "dependent set A, B") << "a displaced member stays in its set";
    const auto again = s.schedule_lost(j.id);
    ASSERT_TRUE(again.ok) << again.reason;
    s.commit(again.transaction);
  }
  for (const auto& id : s.node_ids()) {
    EXPECT_EQ(violations(s, id, s.world(), s.frozen_horizon_time()), std::vector<std::string>{});
  }
}

}  // namespace
}  // namespace oscar::swarm
