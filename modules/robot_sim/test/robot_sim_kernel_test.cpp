// The simulated robot's pilot with the harness's clock (process() runs at the harness time; a
// command is measured against the last cycle's time), and several robots in one module process.
#include "robot_sim_kernel.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/harness.hpp>
#include <oscar/module.hpp>
#include <oscar/swarm_yaml.hpp>
#include <oscar/testing/conformance.hpp>
#include <oscar/testing/eventually.hpp>

namespace oscar::modules {
namespace {
using testing::HasSubstr;
using testing::MatchesRegex;
using testing::StartsWith;

constexpr Stamp kS = 1'000'000'000;  // ns
constexpr Stamp kT0 = 1000 * kS;     // the harness's time when a test begins

SwarmWaypoint wp(double x, double y, Stamp t) {
  SwarmWaypoint w;
  w.x(x);
  w.y(y);
  w.t_ns(t);
  return w;
}

TrajectorySection closed(Stamp from, Stamp to, std::vector<SwarmWaypoint> w) {
  TrajectorySection s;
  s.from_ns(from);
  s.to_ns(to);
  s.waypoints(std::move(w));
  return s;
}

TrajectorySection open(Stamp from, std::vector<SwarmWaypoint> w) {
  TrajectorySection s = closed(from, 0, std::move(w));
  s.open_end(true);
  return s;
}

// A job worked from `start` to `end`, in a window a second wider on either side.
RobotJob job(const std::string& id, double x, double y, Stamp start, Stamp end) {
  RobotJob j;
  j.id(id);
  j.x(x);
  j.y(y);
  j.start_ns(start);
  j.end_ns(end);
  j.earliest_start_ns(start - 1'000'000'000);
  j.latest_finish_ns(end + 1'000'000'000);
  return j;
}

Trajectory proposal(const std::string& robot, std::uint64_t tx,
                    std::vector<TrajectorySection> sections, std::vector<RobotJob> added = {},
                    std::vector<std::string> removed = {}) {
  Trajectory t;
  t.robot(robot);
  t.transaction(tx);
  t.sections(std::move(sections));
  t.jobs_added(std::move(added));
  t.jobs_removed(std::move(removed));
  return t;
}

TransactionDecision decision(const std::string& robot, std::uint64_t tx) {
  TransactionDecision d;
  d.robot(robot);
  d.transaction(tx);
  return d;
}

// A robot 'r1' at (0, 0) with max_speed 1 m/s that has run its first cycle at kT0.
struct Robot {
  explicit Robot(const std::string& params = "{}") : h("robot_sim", YAML::Load(params), "r1") {
    h.set_now(kT0);
    h.step();
    h.take_count("state");
  }
  CommandAnswer propose(const Trajectory& t) { return h.command("propose", t); }
  CommandAnswer commit(std::uint64_t tx) { return h.command("commit", decision("r1", tx)); }
  CommandAnswer abort(std::uint64_t tx) { return h.command("abort", decision("r1", tx)); }
  /// Runs a cycle at kT0 + `s` seconds and returns the state it published.
  RobotState at(double s) {
    h.set_now(kT0 + static_cast<Stamp>(std::llround(s * 1e9)));
    h.step();
    const auto out = h.take<RobotState>("state");
    EXPECT_EQ(out.size(), 1u);
    return out.empty() ? RobotState{} : *out.back();
  }
  CommandAnswer ask_committed(const std::string& robot = "r1") {
    CommittedPlanQuery q;
    q.robot(robot);
    return h.command("committed", q);
  }
  /// The committed plan the robot tells now.
  Trajectory committed() {
    const auto a = ask_committed();
    EXPECT_TRUE(a.accepted) << a.text;
    return trajectory_from_yaml(a.text);
  }
  std::string nak(const Trajectory& t) {
    const auto a = propose(t);
    EXPECT_FALSE(a.accepted) << a.text;
    const auto c = commit(t.transaction());
    EXPECT_FALSE(c.accepted) << "a refused proposal is not kept";
    return a.text;
  }
  KernelHarness h;
};

Stamp at_s(double s) { return kT0 + static_cast<Stamp>(std::llround(s * 1e9)); }

OSCAR_KERNEL_CONFORMANCE_TEST(RobotSim, "robot_sim", "{radius: 0.4, start_x: 2}")

TEST(RobotSim, StandsAtItsStartAndPublishesItsStateEveryCycle) {
  Robot r(
      "{radius: 0.4, max_speed: 1.5, turning_radius: 0.2, start_x: 3, start_y: -2, "
      "start_heading: 1}");
  for (const double s : {0.1, 0.2, 60.0}) {
    const auto st = r.at(s);
    EXPECT_EQ(st.header().source(), "r1/state");
    EXPECT_EQ(st.header().stamps().at(0), static_cast<std::uint64_t>(at_s(s)));
    EXPECT_EQ(st.robot(), "r1");
    EXPECT_EQ(st.radius(), 0.4);
    EXPECT_EQ(st.max_speed(), 1.5);
    EXPECT_EQ(st.turning_radius(), 0.2);
    EXPECT_EQ(st.x(), 3);
    EXPECT_EQ(st.y(), -2);
    EXPECT_EQ(st.heading(), 1);
    EXPECT_EQ(st.speed(), 0);
    EXPECT_EQ(st.job().id(), "");
    EXPECT_EQ(st.transaction(), 0u);
    EXPECT_FALSE(st.broken());
    EXPECT_EQ(st.fault(), "");
  }
}

TEST(RobotSim, FollowsACommittedTrajectoryWithItsJobAndTransaction) {
  Robot r("{start_heading: 1}");
  const auto p =
      proposal("r1", 7, {open(at_s(1), {wp(0, 0, at_s(1)), wp(2, 0, at_s(3)), wp(2, 1, at_s(4))})},
               {job("j1", 2, 1, at_s(5), at_s(7))});
  auto answer = r.propose(p);
  EXPECT_TRUE(answer.accepted) << answer.text;
  EXPECT_EQ(answer.text, "transaction 7 pending: 1 section(s), 1 job(s) added, 0 removed");
  answer = r.commit(7);
  EXPECT_TRUE(answer.accepted) << answer.text;
  EXPECT_EQ(answer.text, "transaction 7 committed: 1 section(s), 1 job(s) added, 0 removed");

  auto st = r.at(0.5);  // before the section: standing at the start
  EXPECT_EQ(st.x(), 0);
  EXPECT_EQ(st.heading(), 1);
  EXPECT_EQ(st.speed(), 0);
  EXPECT_EQ(st.transaction(), 0u);
  st = r.at(2);
  EXPECT_DOUBLE_EQ(st.x(), 1);
  EXPECT_DOUBLE_EQ(st.y(), 0);
  EXPECT_DOUBLE_EQ(st.heading(), 0);
  EXPECT_DOUBLE_EQ(st.speed(), 1);
  EXPECT_EQ(st.transaction(), 7u);
  EXPECT_EQ(st.job().id(), "");
  st = r.at(3.5);
  EXPECT_DOUBLE_EQ(st.x(), 2);
  EXPECT_DOUBLE_EQ(st.y(), 0.5);
  EXPECT_DOUBLE_EQ(st.heading(), M_PI / 2);
  EXPECT_DOUBLE_EQ(st.speed(), 1);
  EXPECT_EQ(st.transaction(), 7u);
  st = r.at(6);  // at the job's place within its window, standing
  EXPECT_DOUBLE_EQ(st.x(), 2);
  EXPECT_DOUBLE_EQ(st.y(), 1);
  EXPECT_DOUBLE_EQ(st.heading(), M_PI / 2) << "the heading is kept while standing";
  EXPECT_EQ(st.speed(), 0);
  EXPECT_EQ(st.job().id(), "j1");
  EXPECT_EQ(st.job(), job("j1", 2, 1, at_s(5), at_s(7))) << "the job as committed, window and all";
  EXPECT_EQ(st.transaction(), 0u) << "after its last waypoint it drives no section";
  st = r.at(7.5);
  EXPECT_EQ(st.job().id(), "") << "the job's window has passed";
  EXPECT_DOUBLE_EQ(st.y(), 1);
  EXPECT_FALSE(st.broken());
}

// Command `committed`: a coordinator that restarted reads what the robot drives and works.
TEST(RobotSim, CommittedTellsItsTrajectoryFromNowAndItsJobsNotYetDone) {
  Robot r;
  ASSERT_TRUE(
      r.propose(proposal("r1", 7,
                         {open(at_s(1), {wp(0, 0, at_s(1)), wp(2, 0, at_s(3)), wp(2, 1, at_s(4))})},
                         {job("j2", 2, 1, at_s(8), at_s(9)), job("j1", 2, 1, at_s(5), at_s(7))}))
          .accepted);
  ASSERT_TRUE(r.commit(7).accepted);
  // Pending proposals are not committed: they are not told.
  ASSERT_TRUE(
      r.propose(proposal("r1", 8, {open(at_s(10), {wp(2, 1, at_s(10)), wp(0, 1, at_s(12))})},
                         {job("j3", 0, 1, at_s(12), at_s(13))}))
          .accepted);
  r.at(2);
  auto plan = r.committed();
  EXPECT_EQ(plan.robot(), "r1");
  EXPECT_EQ(plan.transaction(), 0u);
  ASSERT_EQ(plan.sections().size(), 1u);
  const auto& s = plan.sections()[0];
  EXPECT_TRUE(s.open_end());
  // From the command's time (the last cycle's plus the time since) on: its place then, then the
  // committed waypoints after it.
  EXPECT_GE(s.from_ns(), at_s(2));
  EXPECT_LT(s.from_ns(), at_s(2.5));
  ASSERT_EQ(s.waypoints().size(), 3u);
  EXPECT_EQ(s.waypoints()[0].t_ns(), s.from_ns());
  EXPECT_NEAR(s.waypoints()[0].x(), 1 + static_cast<double>(s.from_ns() - at_s(2)) * 1e-9, 1e-9);
  EXPECT_EQ(s.waypoints()[0].y(), 0);
  EXPECT_EQ(s.waypoints()[1], wp(2, 0, at_s(3)));
  EXPECT_EQ(s.waypoints()[2], wp(2, 1, at_s(4)));
  EXPECT_EQ(s.to_ns(), at_s(4)) << "its last waypoint";
  ASSERT_EQ(plan.jobs_added().size(), 2u);
  EXPECT_EQ(plan.jobs_added()[0], job("j1", 2, 1, at_s(5), at_s(7))) << "by start, as committed";
  EXPECT_EQ(plan.jobs_added()[1], job("j2", 2, 1, at_s(8), at_s(9)));
  EXPECT_TRUE(plan.jobs_removed().empty());

  r.at(7.5);  // j1 is done; it stands at (2, 1) for good
  plan = r.committed();
  ASSERT_EQ(plan.sections().size(), 1u);
  ASSERT_EQ(plan.sections()[0].waypoints().size(), 1u);
  EXPECT_EQ(plan.sections()[0].waypoints()[0].x(), 2);
  EXPECT_EQ(plan.sections()[0].waypoints()[0].y(), 1);
  EXPECT_EQ(plan.sections()[0].to_ns(), plan.sections()[0].from_ns());
  ASSERT_EQ(plan.jobs_added().size(), 1u);
  EXPECT_EQ(plan.jobs_added()[0].id(), "j2");
}

TEST(RobotSim, CommittedOfAnIdleRobotIsWhereItStandsAndNoJob) {
  Robot r("{start_x: 3, start_y: -2}");
  const auto plan = r.committed();
  ASSERT_EQ(plan.sections().size(), 1u);
  ASSERT_EQ(plan.sections()[0].waypoints().size(), 1u);
  EXPECT_EQ(plan.sections()[0].waypoints()[0].x(), 3);
  EXPECT_EQ(plan.sections()[0].waypoints()[0].y(), -2);
  EXPECT_TRUE(plan.jobs_added().empty());
  const auto refused = r.ask_committed("r2");
  EXPECT_FALSE(refused.accepted);
  EXPECT_EQ(refused.text, "the query is for robot 'r2', not 'r1'");
}

TEST(RobotSim, CommittedOfABrokenRobotIsWhereItStoppedAndNoJob) {
  Robot r("{breakdown_after_s: 2}");
  ASSERT_TRUE(r.propose(proposal("r1", 1, {open(at_s(1), {wp(0, 0, at_s(1)), wp(3, 0, at_s(4))})},
                                 {job("j1", 3, 0, at_s(4), at_s(9))}))
                  .accepted);
  ASSERT_TRUE(r.commit(1).accepted);
  r.at(2.5);
  const auto plan = r.committed();
  ASSERT_EQ(plan.sections()[0].waypoints().size(), 1u);
  EXPECT_DOUBLE_EQ(plan.sections()[0].waypoints()[0].x(), 1.5);
  EXPECT_TRUE(plan.jobs_added().empty());
}

TEST(RobotSim, AnUncommittedProposalChangesNothing) {
  Robot r;
  const auto p = proposal("r1", 7, {open(at_s(1), {wp(0, 0, at_s(1)), wp(2, 0, at_s(3))})},
                          {job("j1", 2, 0, at_s(3), at_s(5))});
  ASSERT_TRUE(r.propose(p).accepted);
  for (const double s : {2.0, 4.0}) {
    const auto st = r.at(s);
    EXPECT_EQ(st.x(), 0);
    EXPECT_EQ(st.speed(), 0);
    EXPECT_EQ(st.transaction(), 0u);
    EXPECT_EQ(st.job().id(), "");
  }
}

TEST(RobotSim, AbortDropsTheProposal) {
  Robot r;
  ASSERT_TRUE(r.propose(proposal("r1", 7, {open(at_s(1), {wp(0, 0, at_s(1)), wp(2, 0, at_s(3))})}))
                  .accepted);
  auto answer = r.abort(7);
  EXPECT_TRUE(answer.accepted);
  EXPECT_EQ(answer.text, "transaction 7 aborted: its proposal is dropped");
  answer = r.commit(7);
  EXPECT_FALSE(answer.accepted);
  EXPECT_EQ(answer.text, "no proposal of transaction 7 is pending (none is)");
  EXPECT_EQ(r.at(2).x(), 0);
}

// A coordinator that restarted forgot its open transactions: their proposals do not stay for
// good, only until they began `undecided_for` ago.
TEST(RobotSim, AProposalNobodyDecidesOnIsDroppedOnceItBeganLongAgo) {
  Robot r("{undecided_for: 5s}");
  ASSERT_TRUE(r.propose(proposal("r1", 7, {open(at_s(1), {wp(0, 0, at_s(1)), wp(2, 0, at_s(3))})}))
                  .accepted);
  ASSERT_TRUE(r.propose(proposal("r1", 8, {open(at_s(5), {wp(0, 0, at_s(5)), wp(0, 2, at_s(7))})}))
                  .accepted);
  r.at(5.9);  // 4.9 s after 7 began: kept
  EXPECT_EQ(r.abort(9).text, "no proposal of transaction 9 is pending (pending: 7, 8)");
  r.at(6.1);
  EXPECT_EQ(r.commit(7).text, "no proposal of transaction 7 is pending (pending: 8)");
  EXPECT_EQ(r.at(6.2).x(), 0) << "the dropped proposal changed nothing";
  EXPECT_TRUE(r.commit(8).accepted);
}

TEST(RobotSim, ADecisionOnAnUnknownTransactionOrForAnotherRobotIsRefused) {
  Robot r;
  ASSERT_TRUE(r.propose(proposal("r1", 4, {open(at_s(1), {wp(0, 0, at_s(1)), wp(1, 0, at_s(2))})}))
                  .accepted);
  ASSERT_TRUE(r.propose(proposal("r1", 3, {open(at_s(1), {wp(0, 0, at_s(1)), wp(0, 1, at_s(2))})}))
                  .accepted);
  EXPECT_EQ(r.commit(9).text, "no proposal of transaction 9 is pending (pending: 3, 4)");
  EXPECT_EQ(r.abort(9).text, "no proposal of transaction 9 is pending (pending: 3, 4)");
  const auto other = r.h.command("commit", decision("r2", 3));
  EXPECT_FALSE(other.accepted);
  EXPECT_EQ(other.text, "the decision is for robot 'r2', not 'r1'");
  EXPECT_EQ(r.h.command("abort", decision("r2", 3)).text,
            "the decision is for robot 'r2', not 'r1'");
  EXPECT_TRUE(r.commit(3).accepted) << "the refusals changed nothing";
  EXPECT_DOUBLE_EQ(r.at(2).y(), 1);
}

TEST(RobotSim, AProposalAgainForItsTransactionReplacesThePendingOne) {
  Robot r;
  ASSERT_TRUE(r.propose(proposal("r1", 5, {open(at_s(1), {wp(0, 0, at_s(1)), wp(1, 0, at_s(2))})}))
                  .accepted);
  const auto again =
      r.propose(proposal("r1", 5, {open(at_s(1), {wp(0, 0, at_s(1)), wp(0, 1, at_s(2))})}));
  EXPECT_EQ(again.text,
            "transaction 5 pending: 1 section(s), 0 job(s) added, 0 removed (replaces its earlier "
            "proposal)");
  ASSERT_TRUE(r.commit(5).accepted);
  const auto st = r.at(3);
  EXPECT_EQ(st.x(), 0);
  EXPECT_DOUBLE_EQ(st.y(), 1);
}

TEST(RobotSim, TwoPendingProposalsOnDisjointSectionsBothCommit) {
  Robot r;
  ASSERT_TRUE(r.propose(proposal("r1", 1, {open(at_s(1), {wp(0, 0, at_s(1)), wp(4, 0, at_s(5))})}))
                  .accepted);
  ASSERT_TRUE(r.commit(1).accepted);
  // A detour up and back in [6 s, 8 s], and from 9 s on to (6, 0).
  const auto detour = proposal(
      "r1", 2,
      {closed(at_s(6), at_s(8), {wp(4, 0, at_s(6)), wp(4, 1, at_s(7)), wp(4, 0, at_s(8))})},
      {job("up", 4, 1, at_s(7), at_s(7))});
  const auto onwards =
      proposal("r1", 3, {open(at_s(9), {wp(4, 0, at_s(9)), wp(6, 0, at_s(11))})}, {}, {});
  auto a = r.propose(detour);
  ASSERT_TRUE(a.accepted) << a.text;
  a = r.propose(onwards);
  ASSERT_TRUE(a.accepted) << a.text;
  ASSERT_TRUE(r.commit(3).accepted);  // the later section first: each replaces only its span
  ASSERT_TRUE(r.commit(2).accepted);

  auto st = r.at(3);
  EXPECT_DOUBLE_EQ(st.x(), 2);
  EXPECT_EQ(st.transaction(), 1u);
  st = r.at(7);
  EXPECT_DOUBLE_EQ(st.x(), 4);
  EXPECT_DOUBLE_EQ(st.y(), 1);
  EXPECT_EQ(st.transaction(), 2u);
  EXPECT_EQ(st.job().id(), "up");
  st = r.at(7.5);
  EXPECT_DOUBLE_EQ(st.y(), 0.5);
  EXPECT_DOUBLE_EQ(st.heading(), -M_PI / 2);
  st = r.at(8.5);
  EXPECT_DOUBLE_EQ(st.x(), 4);
  EXPECT_DOUBLE_EQ(st.y(), 0);
  EXPECT_EQ(st.speed(), 0);
  EXPECT_EQ(st.transaction(), 0u);
  st = r.at(10);
  EXPECT_DOUBLE_EQ(st.x(), 5);
  EXPECT_DOUBLE_EQ(st.heading(), 0);
  EXPECT_EQ(st.transaction(), 3u);
  st = r.at(12);
  EXPECT_DOUBLE_EQ(st.x(), 6);
  EXPECT_EQ(st.transaction(), 0u);
}

TEST(RobotSim, CommittedJobsAreRemovedByALaterTransaction) {
  Robot r;
  ASSERT_TRUE(r.propose(proposal("r1", 1, {}, {job("j1", 0, 0, at_s(1), at_s(9))})).accepted);
  ASSERT_TRUE(r.commit(1).accepted);
  EXPECT_EQ(r.at(2).job().id(), "j1");
  ASSERT_TRUE(
      r.propose(proposal("r1", 2, {}, {job("j2", 0, 0, at_s(5), at_s(6))}, {"j1"})).accepted);
  EXPECT_EQ(r.at(3).job().id(), "j1") << "until the commit";
  const auto c = r.commit(2);
  EXPECT_EQ(c.text, "transaction 2 committed: 0 section(s), 1 job(s) added, 1 removed");
  EXPECT_EQ(r.at(4).job().id(), "");
  EXPECT_EQ(r.at(5.5).job().id(), "j2");
}

// --- NAK reasons ------------------------------------------------------------------------------

TEST(RobotSimNak, AProposalForAnotherRobot) {
  Robot r;
  EXPECT_EQ(r.nak(proposal("r2", 1, {open(at_s(1), {wp(0, 0, at_s(1))})})),
            "the proposal is for robot 'r2', not 'r1'");
}

TEST(RobotSimNak, ASectionThatDoesNotStartWhereTheRobotWillBe) {
  Robot r;
  EXPECT_EQ(r.nak(proposal("r1", 1, {open(at_s(1), {wp(0.5, 0, at_s(1)), wp(1, 0, at_s(2))})})),
            "section 0 does not start where the robot will be at 1001000000000 ns: (0.500, 0.000) "
            "vs (0.000, 0.000)");
  // Within 1 cm it does; and the place counts on the committed trajectory at from_ns.
  ASSERT_TRUE(
      r.propose(proposal("r1", 2, {open(at_s(1), {wp(0.009, 0, at_s(1)), wp(1, 0, at_s(2))})}))
          .accepted);
  ASSERT_TRUE(r.commit(2).accepted);
  EXPECT_EQ(r.nak(proposal("r1", 3, {open(at_s(3), {wp(0, 0, at_s(3))})})),
            "section 0 does not start where the robot will be at 1003000000000 ns: (0.000, 0.000) "
            "vs (1.000, 0.000)");
  EXPECT_TRUE(r.propose(proposal("r1", 4, {open(at_s(3), {wp(1, 0, at_s(3))})})).accepted);
}

TEST(RobotSimNak, AClosedSectionThatDoesNotEndWhereTheRobotWillBe) {
  Robot r;
  EXPECT_EQ(
      r.nak(proposal("r1", 1, {closed(at_s(1), at_s(3), {wp(0, 0, at_s(1)), wp(1, 0, at_s(2))})})),
      "section 0 does not end where the robot will be at 1003000000000 ns: (1.000, 0.000) vs "
      "(0.000, 0.000)");
}

TEST(RobotSimNak, ALegFasterThanMaxSpeed) {
  Robot r;
  EXPECT_EQ(r.nak(proposal("r1", 1, {open(at_s(1), {wp(0, 0, at_s(1)), wp(3, 0, at_s(2))})})),
            "section 0: the leg from (0.000, 0.000) at 1001000000000 ns to (3.000, 0.000) at "
            "1002000000000 ns needs 3.000 m/s, more than max_speed 1 m/s");
  EXPECT_EQ(r.nak(proposal("r1", 2, {open(at_s(1), {wp(0, 0, at_s(1)), wp(1, 0, at_s(1))})})),
            "section 0: the leg from (0.000, 0.000) at 1001000000000 ns to (1.000, 0.000) at "
            "1001000000000 ns needs inf m/s, more than max_speed 1 m/s");
  EXPECT_TRUE(
      r.propose(proposal("r1", 3, {open(at_s(1), {wp(0, 0, at_s(1)), wp(1.00005, 0, at_s(2))})}))
          .accepted)
      << "a small relative tolerance";
}

// How long before its arrival a refused proposal's section started, as the refusal says: the
// harness's time at the last step plus the real time since (which a loaded machine stretches).
double ms_before_arrival(const std::string& refusal) {
  const auto comma = refusal.rfind(", ");
  return comma == std::string::npos ? -1 : std::stod(refusal.substr(comma + 2));
}

TEST(RobotSimNak, AProposalThatArrivesTooLateToTakeOver) {
  Robot r;
  auto text = r.nak(proposal("r1", 1, {open(at_s(-0.005), {wp(0, 0, at_s(-0.005))})}));
  EXPECT_THAT(text, MatchesRegex("the proposal arrives too late to take over: section 0 starts at "
                                 "999995000000 ns, [0-9]+\\.[0-9] ms before it arrived"));
  EXPECT_GE(ms_before_arrival(text), 5.0);
  text = r.nak(proposal(
      "r1", 2, {open(at_s(1), {wp(0, 0, at_s(1))}), closed(kT0, at_s(0.5), {wp(0, 0, kT0)})}));
  EXPECT_THAT(text, MatchesRegex("the proposal arrives too late to take over: section 1 starts at "
                                 "1000000000000 ns, [0-9]+\\.[0-9] ms before it arrived"))
      << "a section starting at the last cycle's time is too late";
  EXPECT_GE(ms_before_arrival(text), 0.0);
  EXPECT_TRUE(r.propose(proposal("r1", 3, {open(at_s(0.5), {wp(0, 0, at_s(0.5))})})).accepted);
}

TEST(RobotSimNak, WaypointTimesThatDecreaseOrLieOutsideTheSection) {
  Robot r;
  EXPECT_EQ(r.nak(proposal("r1", 1, {open(at_s(1), {wp(0, 0, at_s(2)), wp(0, 0, at_s(1.5))})})),
            "section 0: the waypoints' times decrease: waypoint 0 at 1002000000000 ns, 1 at "
            "1001500000000 ns");
  EXPECT_EQ(
      r.nak(proposal("r1", 2, {closed(at_s(1), at_s(3), {wp(0, 0, at_s(1)), wp(0, 0, at_s(4))})})),
      "section 0: waypoint 1 at 1004000000000 ns is outside the section [1001000000000, "
      "1003000000000]");
  EXPECT_EQ(r.nak(proposal("r1", 3, {open(at_s(1), {wp(0, 0, at_s(0.5)), wp(0, 0, at_s(2))})})),
            "section 0: waypoint 0 at 1000500000000 ns is outside the section [1001000000000, "
            "open end]");
}

TEST(RobotSimNak, MalformedSectionsJobsAndTransactions) {
  Robot r;
  EXPECT_EQ(r.nak(proposal("r1", 1, {open(at_s(1), {})})), "section 0 has no waypoints");
  EXPECT_EQ(r.nak(proposal("r1", 2, {closed(at_s(2), at_s(1), {wp(0, 0, at_s(1))})})),
            "section 0 ends at 1001000000000 ns, before it starts at 1002000000000 ns");
  EXPECT_EQ(r.nak(proposal("r1", 3,
                           {closed(at_s(1), at_s(3), {wp(0, 0, at_s(1)), wp(0, 0, at_s(3))}),
                            closed(at_s(2), at_s(4), {wp(0, 0, at_s(2)), wp(0, 0, at_s(4))})})),
            "sections 0 and 1 overlap");
  EXPECT_EQ(r.nak(proposal("r1", 4,
                           {closed(at_s(5), at_s(6), {wp(0, 0, at_s(5)), wp(0, 0, at_s(6))}),
                            open(at_s(1), {wp(0, 0, at_s(1))})})),
            "sections 1 and 0 overlap")
      << "an open-ended section must come last";
  EXPECT_EQ(r.nak(proposal("r1", 5, {open(at_s(1), {wp(NAN, 0, at_s(1))})})),
            "section 0: waypoint 0 is no finite place");
  EXPECT_EQ(r.nak(proposal("r1", 0, {open(at_s(1), {wp(0, 0, at_s(1))})})),
            "transaction 0 names no transaction");
  EXPECT_EQ(r.nak(proposal("r1", 6, {}, {job("j", 0, 0, at_s(2), at_s(1))})),
            "job 'j' ends at 1001000000000 ns, before it starts at 1002000000000 ns");
  EXPECT_EQ(r.nak(proposal("r1", 7, {}, {job("", 0, 0, at_s(1), at_s(2))})),
            "a job added has no id");
  EXPECT_TRUE(r.propose(proposal("r1", 8,
                                 {closed(at_s(1), at_s(3), {wp(0, 0, at_s(1)), wp(0, 0, at_s(3))}),
                                  open(at_s(3), {wp(0, 0, at_s(3))})}))
                  .accepted)
      << "sections may touch";
}

// --- faults -----------------------------------------------------------------------------------

TEST(RobotSimFaults, NakProbabilityOneRefusesEveryProposalAndZeroNone) {
  const auto valid = [](std::uint64_t tx) {
    return proposal("r1", tx, {open(at_s(1), {wp(0, 0, at_s(1)), wp(1, 0, at_s(2))})});
  };
  Robot always("{nak_probability: 1}");
  Robot never("{nak_probability: 0}");
  for (std::uint64_t tx = 1; tx <= 20; ++tx) {
    EXPECT_EQ(always.nak(valid(tx)), "refused by fault injection (nak_probability 1)");
    EXPECT_TRUE(never.propose(valid(tx)).accepted);
  }
  EXPECT_EQ(always.nak(proposal("r2", 99, {})), "the proposal is for robot 'r2', not 'r1'")
      << "a proposal the robot cannot take is refused for its own reason";
}

TEST(RobotSimFaults, RandomRefusalsFollowTheSeed) {
  const auto answers = [](const std::string& params) {
    Robot r(params);
    std::string a;
    for (std::uint64_t tx = 1; tx <= 40; ++tx) {
      a += r.propose(proposal("r1", tx, {open(at_s(1), {wp(0, 0, at_s(1))})})).accepted ? 'A' : 'N';
    }
    return a;
  };
  const auto a = answers("{nak_probability: 0.5, seed: 3}");
  EXPECT_EQ(a, answers("{nak_probability: 0.5, seed: 3}")) << "reproducible";
  EXPECT_NE(a, answers("{nak_probability: 0.5, seed: 4}"));
  EXPECT_THAT(a, HasSubstr("A"));
  EXPECT_THAT(a, HasSubstr("N"));
}

TEST(RobotSimFaults, ABreakdownStopsTheRobotWhereItIsAndItRefusesEverythingSince) {
  Robot r("{breakdown_after_s: 2}");  // activated at its first cycle, kT0
  ASSERT_TRUE(r.propose(proposal("r1", 1, {open(at_s(1), {wp(0, 0, at_s(1)), wp(3, 0, at_s(4))})},
                                 {job("j1", 3, 0, at_s(1), at_s(9))}))
                  .accepted);
  ASSERT_TRUE(r.commit(1).accepted);
  ASSERT_TRUE(r.propose(proposal("r1", 2, {open(at_s(5), {wp(3, 0, at_s(5)), wp(3, 1, at_s(6))})}))
                  .accepted);
  auto st = r.at(1.5);
  EXPECT_FALSE(st.broken());
  EXPECT_DOUBLE_EQ(st.x(), 0.5);
  EXPECT_EQ(st.job().id(), "j1");
  st = r.at(2.5);
  EXPECT_TRUE(st.broken());
  EXPECT_EQ(st.fault(), "broke down 2 s after activation (fault injection: breakdown_after_s)");
  EXPECT_DOUBLE_EQ(st.x(), 1.5) << "it stops where it is";
  EXPECT_EQ(st.speed(), 0);
  EXPECT_EQ(st.transaction(), 0u);
  EXPECT_EQ(st.job().id(), "");
  st = r.at(5.5);
  EXPECT_TRUE(st.broken());
  EXPECT_DOUBLE_EQ(st.x(), 1.5);
  EXPECT_DOUBLE_EQ(st.heading(), 0);
  const std::string broken =
      "robot 'r1' is broken: broke down 2 s after activation (fault injection: "
      "breakdown_after_s)";
  EXPECT_EQ(r.nak(proposal("r1", 3, {open(at_s(7), {wp(1.5, 0, at_s(7))})})), broken);
  auto c = r.commit(2);
  EXPECT_FALSE(c.accepted);
  EXPECT_EQ(c.text, broken + "; it cannot drive transaction 2");
  EXPECT_TRUE(r.abort(2).accepted);
}

TEST(RobotSimFaults, ABreakdownIsNoticedByACommandBeforeTheNextCycle) {
  Robot r("{breakdown_after_s: 0.05}");
  std::this_thread::sleep_for(std::chrono::milliseconds(60));  // a command's time runs on
  EXPECT_THAT(r.nak(proposal("r1", 1, {open(at_s(1), {wp(0, 0, at_s(1))})})),
              StartsWith("robot 'r1' is broken: "));
  EXPECT_TRUE(r.at(0.1).broken());
}

TEST(RobotSimFaults, AckDelayDelaysTheAnswerWhichIsJudgedOnArrival) {
  using Clock = std::chrono::steady_clock;
  const auto timed = [](Robot& r, const Trajectory& t) {
    const auto begin = Clock::now();
    const auto a = r.propose(t);
    return std::make_pair(a, Clock::now() - begin);
  };
  const auto soon = [](std::uint64_t tx) {  // from 250 ms after the last cycle on
    return proposal("r1", tx, {open(at_s(0.25), {wp(0, 0, at_s(0.25)), wp(0, 0.1, at_s(0.5))})});
  };
  Robot slow("{ack_delay_ms: 300}");
  auto [a, took] = timed(slow, soon(1));
  EXPECT_TRUE(a.accepted) << a.text;
  EXPECT_GE(took, std::chrono::milliseconds(300));
  std::tie(a, took) = timed(slow, proposal("r2", 2, {}));
  EXPECT_FALSE(a.accepted) << "a NAK waits too";
  EXPECT_GE(took, std::chrono::milliseconds(300));
  Robot quick;
  std::tie(a, took) = timed(quick, soon(1));
  EXPECT_TRUE(a.accepted);
  EXPECT_LT(took, std::chrono::milliseconds(250));
}

TEST(RobotSim, StubStandsAtTheStartWhateverItWasToldToDo) {
  Robot r("{start_x: 3, start_y: 4, start_heading: 1}");
  ASSERT_TRUE(r.propose(proposal("r1", 1, {open(at_s(1), {wp(3, 4, at_s(1)), wp(4, 4, at_s(2))})}))
                  .accepted);
  ASSERT_TRUE(r.commit(1).accepted);
  r.h.set_now(at_s(1.5));
  r.h.step_stub();
  const auto out = r.h.take<RobotState>("state");
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0]->robot(), "r1");
  EXPECT_EQ(out[0]->x(), 3);
  EXPECT_EQ(out[0]->y(), 4);
  EXPECT_EQ(out[0]->heading(), 1);
  EXPECT_EQ(out[0]->speed(), 0);
  EXPECT_EQ(out[0]->header().stamps().at(0), static_cast<std::uint64_t>(at_s(1.5)));
  EXPECT_DOUBLE_EQ(r.at(1.5).x(), 3.5) << "process() drives the committed trajectory again";
}

TEST(RobotSim, BadParametersAreRefusedAtLoadTime) {
  EXPECT_THROW(KernelHarness("robot_sim", YAML::Load("{max_speed: 0}")), std::invalid_argument);
  EXPECT_THROW(KernelHarness("robot_sim", YAML::Load("{nak_probability: 1.5}")),
               std::invalid_argument);
  EXPECT_THROW(KernelHarness("robot_sim", YAML::Load("{radius: -1}")), std::invalid_argument);
}

// --- several robots in one module process -----------------------------------------------------

ConfigCommand command(const std::string& kernel, const std::string& name, const auto& request) {
  using T = std::decay_t<decltype(request)>;
  ConfigCommand c;
  c.id(1);
  c.sender("coordinator");
  c.kind(CMD_COMMAND);
  c.args({kernel, name});
  c.payload_type(idl_type_info<T>().name);
  c.payload(idl_type_info<T>().serialize(&request));
  return c;
}

std::shared_ptr<const RobotState> latest(Module& m, const std::string& robot) {
  const auto e = m.kernel(robot).ports().find_output("state")->buffer().latest();
  return e ? std::static_pointer_cast<const RobotState>(e->cue) : nullptr;
}

TEST(RobotSimModule, SeveralRobotsInOneModuleEachFollowTheirOwnTrajectory) {
  Module m(ModuleSpec::from_yaml(YAML::Load(R"(
name: robots
mode: { continuous: 20ms }
kernels:
  - { type: robot_sim, name: r1, params: { start_x: 0 } }
  - { type: robot_sim, name: r2, params: { start_x: 10 }, mode: { single_step: { trigger: module } } }
  - { type: robot_sim, name: r3, params: { start_x: 20 }, mode: { single_step: { trigger: module } } }
)"),
                                 "robots.yaml"),
           {});
  m.start(-1);
  ASSERT_TRUE(eventually([&] { return latest(m, "r2") && latest(m, "r3"); }))
      << "the continuous robot triggers the others";
  EXPECT_EQ(latest(m, "r3")->x(), 20);

  const struct {
    std::string robot;
    double x0, dx, dy;
  } plans[] = {{"r1", 0, 0, 0.5}, {"r2", 10, 0, -0.5}, {"r3", 20, 0.5, 0}};
  const Stamp from = wall_now() + 800'000'000;  // 800 ms ahead, then 0.5 m in 0.5 s
  std::uint64_t tx = 11;
  for (const auto& p : plans) {
    const auto t = proposal(
        p.robot, tx, {open(from, {wp(p.x0, 0, from), wp(p.x0 + p.dx, p.dy, from + 500'000'000)})});
    auto reply = m.apply(command(p.robot, "propose", t));
    ASSERT_TRUE(reply.ok()) << reply.error();
    EXPECT_EQ(reply.answer(), fmt::format("transaction {} pending: 1 section(s), 0 job(s) added, "
                                          "0 removed",
                                          tx));
    reply = m.apply(command(p.robot, "commit", decision(p.robot, tx)));
    ASSERT_TRUE(reply.ok()) << reply.error();
    ++tx;
  }
  // While they drive, each reports its own transaction and speed.
  std::map<std::string, bool> seen_driving;
  ASSERT_TRUE(eventually(
      [&] {
        tx = 11;
        for (const auto& p : plans) {
          const auto s = latest(m, p.robot);
          if (s->transaction() == tx && std::abs(s->speed() - 1) < 1e-6)
            seen_driving[p.robot] = true;
          ++tx;
        }
        return seen_driving.size() == 3;
      },
      std::chrono::seconds(5), std::chrono::milliseconds(1)));
  ASSERT_TRUE(eventually([&] {
    for (const auto& p : plans) {
      const auto s = latest(m, p.robot);
      if (std::abs(s->x() - (p.x0 + p.dx)) > 1e-9 || std::abs(s->y() - p.dy) > 1e-9) return false;
    }
    return true;
  }));
  EXPECT_DOUBLE_EQ(latest(m, "r1")->heading(), M_PI / 2);
  EXPECT_DOUBLE_EQ(latest(m, "r2")->heading(), -M_PI / 2);
  EXPECT_DOUBLE_EQ(latest(m, "r3")->heading(), 0);
  EXPECT_EQ(latest(m, "r2")->header().source(), "r2/state");
  // In the module a command's time is the wall clock's: a section starting now is too late.
  const Stamp past = wall_now() - 1'000'000;
  const auto late =
      m.apply(command("r3", "propose", proposal("r3", 20, {open(past, {wp(20.5, 0, past)})})));
  EXPECT_FALSE(late.ok());
  EXPECT_THAT(late.answer(), StartsWith("the proposal arrives too late to take over"));
}

}  // namespace
}  // namespace oscar::modules
