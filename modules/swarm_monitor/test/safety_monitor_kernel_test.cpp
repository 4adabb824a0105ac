#include "safety_monitor_kernel.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/harness.hpp>
#include <oscar/swarm_types.hpp>
#include <oscar/testing/conformance.hpp>

#include "world_builder.hpp"

namespace oscar::modules {
namespace {
using testing::ElementsAre;
using testing::HasSubstr;
using testing::IsEmpty;
using testing::Not;
using testing::SizeIs;
using testing::ThrowsMessage;
using world_builder::area;
using world_builder::obstacle;
using world_builder::waypoint;
using world_builder::world;

constexpr Stamp kSecond = 1'000'000'000;
constexpr Stamp kT0 = 1'700'000'000 * kSecond;  // a Unix time, a multiple of 20 s

OSCAR_KERNEL_CONFORMANCE_TEST(
    SafetyMonitor, "safety_monitor",
    "{inputs: 'r1, r2', static_obstacles: '[[[0, 0], [1, 0], [1, 1]]]', moving_obstacles: "
    "'[{shape: [[0, 0], [1, 0], [0, 1]], loop: [[0, 0, 0], [1, 0, 5], [0, 0, 10]]}]', "
    "distance_tolerance: 0.002, job_tolerance: 0.1, max_extrapolation: 250ms}")

/// A monitor of the robots `robots`, wired as the configuration's inputs.
KernelHarness monitor(const std::string& params = "{}",
                      const std::vector<std::string>& robots = {"r1", "r2"}) {
  std::map<std::string, InputOverrides> inputs;
  for (const auto& r : robots) inputs[r] = {};
  return KernelHarness("safety_monitor", YAML::Load(params), "monitor", inputs);
}

RobotState robot(const std::string& name, double x, double y, Stamp t, double radius = 0.2) {
  RobotState s;
  s.robot(name);
  s.radius(radius);
  s.max_speed(1);
  s.x(x);
  s.y(y);
  append_stamp(s.header(), t);
  return s;
}

RobotState moving(RobotState s, double speed, double heading) {
  s.speed(speed);
  s.heading(heading);
  return s;
}

RobotState working(RobotState s, const std::string& id, double x, double y, Stamp start, Stamp end,
                   Stamp earliest, Stamp latest) {
  s.job().id(id);
  s.job().x(x);
  s.job().y(y);
  s.job().start_ns(start);
  s.job().end_ns(end);
  s.job().earliest_start_ns(earliest);
  s.job().latest_finish_ns(latest);
  return s;
}

std::vector<std::shared_ptr<const SafetyViolation>> violations(KernelHarness& h) {
  return h.take<SafetyViolation>("violations");
}

const SafetyMonitor& kernel(KernelHarness& h) {
  return dynamic_cast<const SafetyMonitor&>(h.kernel());
}

// --- (1) distance between robots ---

TEST(SafetyMonitor, RobotsJustFartherThanTheirRadiiAreQuietCloserAreReported) {
  auto h = monitor();
  h.feed("r1", robot("r1", 0, 0, kT0));
  h.feed("r2", robot("r2", 0.401, 0, kT0));  // radii 0.2 + 0.2: 1 mm to spare
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());

  h.feed("r2", robot("r2", 0.39, 0, kT0 + kSecond / 10));
  h.set_now(kT0 + kSecond);
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_EQ(v[0]->kind(), "distance");
  EXPECT_THAT(v[0]->robots(), ElementsAre("r1", "r2"));
  EXPECT_EQ(v[0]->job(), "");
  EXPECT_THAT(v[0]->detail(), HasSubstr("r2 and r1 are 0.390 m apart, less than their radii "
                                        "0.200 + 0.200 = 0.400 m (tolerance 0.001 m)"));
  EXPECT_DOUBLE_EQ(v[0]->x(), 0.195);
  EXPECT_DOUBLE_EQ(v[0]->y(), 0);
  EXPECT_EQ(v[0]->count(), 1u);
  // The stamps of the state that showed it, then the monitor's own.
  EXPECT_THAT(v[0]->header().stamps(),
              ElementsAre(static_cast<unsigned long long>(kT0 + kSecond / 10),
                          static_cast<unsigned long long>(kT0 + kSecond)));
  EXPECT_EQ(kernel(h).count("distance"), 1u);
}

TEST(SafetyMonitor, RobotsTouchingWithinTheToleranceAreQuietBeyondItReported) {
  auto h = monitor();
  h.feed("r1", robot("r1", 0, 0, kT0));
  h.feed("r2", robot("r2", 0, 0.3995, kT0));  // 0.5 mm into each other: within 1 mm
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  h.feed("r2", robot("r2", 0, 0.3985, kT0 + 1));  // 1.5 mm
  h.step();
  ASSERT_THAT(violations(h), SizeIs(1));

  // A larger tolerance lets 1.5 mm pass, and not 2.5 mm.
  auto wide = monitor("{distance_tolerance: 0.002}");
  wide.feed("r1", robot("r1", 0, 0, kT0));
  wide.feed("r2", robot("r2", 0, 0.3985, kT0));
  wide.step();
  EXPECT_THAT(violations(wide), IsEmpty());
  wide.feed("r2", robot("r2", 0, 0.3975, kT0 + 1));
  wide.step();
  EXPECT_THAT(violations(wide), SizeIs(1));
}

TEST(SafetyMonitor, StatesOfDifferentStampsAreComparedWhereTheRobotsAreAtTheSameTime) {
  constexpr double kUp = std::numbers::pi / 2;
  // r1 drives up (+y) at 1 m/s; r2 stands 0.4 m ahead. Their states, 0.4 s apart, are 0.4 m
  // apart (radii 0.1 + 0.1): at r2's stamp, r1 has arrived where r2 stands.
  auto h = monitor();
  h.feed("r1", moving(robot("r1", 0, 0, kT0, 0.1), 1, kUp));
  h.step();
  h.feed("r2", robot("r2", 0, 0.4, kT0 + 4 * kSecond / 10, 0.1));
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->detail(), HasSubstr("r2 and r1 are 0.000 m apart"));
  EXPECT_THAT(v[0]->detail(), HasSubstr("r1 at (0.000, 0.400) (its state of -0.400 s "
                                        "extrapolated with 1.000 m/s)"));

  // Two robots driving apart: their states, 0.4 s apart, are 0.15 m apart, but at no time were
  // they closer than 0.25 m.
  auto apart = monitor();
  apart.feed("r1", moving(robot("r1", 0, 0, kT0, 0.1), 1, std::numbers::pi));
  apart.step();
  apart.feed("r2", moving(robot("r2", 0.15, 0, kT0 + 4 * kSecond / 10, 0.1), 1, 0));
  apart.step();
  EXPECT_THAT(violations(apart), IsEmpty());
}

TEST(SafetyMonitor, StatesFartherApartInTimeThanMaxExtrapolationAreNotCompared) {
  // r1's state, extrapolated 0.6 s, would put it on r2; the default limit is 0.5 s.
  auto h = monitor();
  h.feed("r1", moving(robot("r1", 0, 0, kT0, 0.1), 1, 0));
  h.step();
  h.feed("r2", robot("r2", 0.6, 0, kT0 + 6 * kSecond / 10, 0.1));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());

  auto far = monitor("{max_extrapolation: 1s}");
  far.feed("r1", moving(robot("r1", 0, 0, kT0, 0.1), 1, 0));
  far.step();
  far.feed("r2", robot("r2", 0.6, 0, kT0 + 6 * kSecond / 10, 0.1));
  far.step();
  EXPECT_THAT(violations(far), SizeIs(1));
}

TEST(SafetyMonitor, ABrokenRobotStaysAnObstacleHoweverOldItsState) {
  auto h = monitor();
  auto broken = moving(robot("r2", 1, 1, kT0 - 60 * kSecond), 0.5, 0);  // a stale speed
  broken.broken(true);
  broken.fault("motor");
  h.feed("r2", broken);
  h.step();
  h.feed("r1", robot("r1", 1.3, 1, kT0));
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->detail(), HasSubstr("r2 at (1.000, 1.000) (broken down, standing)"));
}

// --- (2) static obstacles ---

TEST(SafetyMonitor, ARobotPassingNextToAStaticObstacleIsQuietOneGrazingItReported) {
  auto h = monitor("{static_obstacles: '[[[2, 0], [4, 0], [4, 2], [2, 2]]]'}", {"r1"});
  // Along the top edge 5 cm clear (radius 0.2), round the corner (4, 2) and down its side.
  // The last point 0.5 mm into it: within the tolerance of 1 mm.
  const std::vector<std::pair<double, double>> path{{1.5, 2.25},   {2.5, 2.25}, {3.5, 2.25},
                                                    {4.15, 2.15},  {4.25, 1.5}, {4.25, 0.5},
                                                    {4.1995, 0.25}};
  Stamp t = kT0;
  for (const auto& [x, y] : path) h.feed("r1", robot("r1", x, y, t += kSecond / 10));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());

  h.feed("r1", robot("r1", 3, 2.15, t += kSecond / 10));  // 5 cm into it from above
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_EQ(v[0]->kind(), "static_obstacle");
  EXPECT_THAT(v[0]->robots(), ElementsAre("r1"));
  EXPECT_THAT(v[0]->detail(),
              HasSubstr("r1 (radius 0.200 m) at (3.000, 2.150) reaches 0.050 m into static "
                        "obstacle 0 (centre outside, 0.150 m from its edge"));
  EXPECT_DOUBLE_EQ(v[0]->x(), 3);
  EXPECT_DOUBLE_EQ(v[0]->y(), 2.15);
}

TEST(SafetyMonitor, ARobotInsideAStaticObstacleIsReportedNamingTheObstacle) {
  auto h = monitor(
      "{static_obstacles: '[[[0, 5], [1, 5], [1, 6]], [[2, 0], [4, 0], [4, 2], [2, 2]]]'}", {"r1"});
  h.feed("r1", robot("r1", 1, 3, kT0));  // clear of both
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  h.feed("r1", robot("r1", 3, 1.5, kT0 + 1));
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->detail(), HasSubstr("reaches 0.700 m into static obstacle 1 (centre inside, "
                                        "0.500 m from its edge"));
  EXPECT_EQ(kernel(h).count("static_obstacle"), 1u);
}

// --- (3) moving obstacles ---

TEST(SafetyMonitor, AMovingObstacleSweepingOverAStandingRobotIsReportedAtItsLoopTime) {
  // A 1 m square drives out along x to (8, 0) in 10 s and back in 10 s; a robot (radius 0.2)
  // stands at (4, 0). The square covers it from loop time 4.125 s to 5.875 s and from 14.125 s
  // to 15.875 s, in every 20 s of the Unix clock.
  auto h = monitor(
      "{moving_obstacles: '[{shape: [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]], "
      "loop: [[0, 0, 0], [8, 0, 10], [0, 0, 20]]}]'}",
      {"r1"});
  constexpr Stamp kPeriod = 20 * kSecond;
  const Stamp t0 = kT0 + 7 * kPeriod;  // the loop's start, long after the monitor's
  auto at = [&](double s) { return t0 + static_cast<Stamp>(s * 1e9); };
  // At 4.125625 s the square's edge is at 3.8005: 0.5 mm into the robot, within the tolerance.
  for (double s : {0.0, 2.0, 4.0, 4.1, 4.125625}) h.feed("r1", robot("r1", 4, 0, at(s)));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());

  h.feed("r1", robot("r1", 4, 0, at(5)));
  h.feed("r1", robot("r1", 4, 0, at(5.5)));  // still covered: the same violation
  h.step();
  auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_EQ(v[0]->kind(), "moving_obstacle");
  EXPECT_THAT(v[0]->detail(),
              HasSubstr("r1 (radius 0.200 m) at (4.000, 0.000) reaches 0.700 m into moving "
                        "obstacle 0 at loop time 5.000 s of 20.000 s, its origin at (4.000, "
                        "0.000) (centre inside"));

  for (double s : {6.0, 10.0, 13.0}) h.feed("r1", robot("r1", 4, 0, at(s)));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  // On its way back, three periods later.
  h.feed("r1", robot("r1", 4, 0, at(3 * 20 + 15)));
  h.step();
  v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->detail(), HasSubstr("at loop time 15.000 s of 20.000 s, its origin at "
                                        "(4.000, 0.000)"));
  EXPECT_EQ(v[0]->count(), 2u);
}

// --- the coordinator's world (command `world`) ---

const SwarmArea kPallet = area({{2, 0}, {4, 0}, {4, 2}, {2, 2}});
const SwarmArea kUnitSquare = area({{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}});

TEST(SafetyMonitor, AStaticObstacleOfTheWorldIsAViolationNamedFromItsSinceOn) {
  auto h = monitor("{}", {"r1"});
  const Stamp since = kT0 + 10 * kSecond;
  const auto answer = h.command("world", world({obstacle("pallet", kPallet, {}, 0, since)}));
  EXPECT_TRUE(answer.accepted);
  EXPECT_EQ(answer.text,
            "world: 1 static, 0 moving obstacles; violations ended with their obstacles: 0");

  // Inside before since_ns: the coordinator added it for later, the robot may still be there.
  h.feed("r1", robot("r1", 3, 1, since - 1));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  h.feed("r1", robot("r1", 3, 1, since));
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_EQ(v[0]->kind(), "static_obstacle");
  EXPECT_THAT(v[0]->detail(), HasSubstr("r1 (radius 0.200 m) at (3.000, 1.000) reaches 1.200 m "
                                        "into static obstacle 'pallet' (centre inside"));
}

TEST(SafetyMonitor, AMovingObstacleOnAPathDrivenOnceIsAViolationOnlyWhileItIsThere) {
  // A 1 m square drives from (0, 0) at kT0 to (8, 0) at kT0 + 8 s, and then leaves the world.
  const auto cart = world(
      {obstacle("cart", kUnitSquare, {waypoint(0, 0, kT0), waypoint(8, 0, kT0 + 8 * kSecond)})});
  // A fresh monitor per state: each judged on its own.
  auto judged = [&](double x, Stamp t) {
    auto h = monitor("{}", {"r1"});
    EXPECT_TRUE(h.command("world", cart).accepted);
    h.feed("r1", robot("r1", x, 0, t));
    h.step();
    return violations(h);
  };
  const auto v = judged(4, kT0 + 4 * kSecond);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_EQ(v[0]->kind(), "moving_obstacle");
  EXPECT_THAT(v[0]->detail(),
              HasSubstr("r1 (radius 0.200 m) at (4.000, 0.000) reaches 0.700 m into moving "
                        "obstacle 'cart' at path time 4.000 s of 8.000 s, its origin at (4.000, "
                        "0.000) (centre inside"));
  EXPECT_THAT(judged(4, kT0 + 1 * kSecond), IsEmpty()) << "the cart is at (1, 0) then";
  EXPECT_THAT(judged(8, kT0 + 8 * kSecond), SizeIs(1)) << "the path's last point counts";
  EXPECT_THAT(judged(8, kT0 + 8 * kSecond + kSecond / 10), IsEmpty()) << "after the path";
  EXPECT_THAT(judged(0, kT0 - kSecond / 10), IsEmpty()) << "before the path";
}

TEST(SafetyMonitor, TheWorldReplacesTheParametersObstacles) {
  const std::string params =
      "{static_obstacles: '[[[2, 0], [4, 0], [4, 2], [2, 2]]]', moving_obstacles: '[{shape: "
      "[[0, 0], [1, 0], [1, 1], [0, 1]], loop: [[20, 0, 0], [20, 0, 10]]}]'}";
  auto inside_both = [](KernelHarness& h) {
    h.feed("r1", robot("r1", 3, 1, kT0));       // in the static obstacle
    h.feed("r2", robot("r2", 20.5, 0.5, kT0));  // in the moving one
    h.step();
    return violations(h);
  };
  auto before = monitor(params);
  EXPECT_THAT(inside_both(before), SizeIs(2)) << "the parameters' obstacles count until then";

  auto h = monitor(params);
  const auto answer =
      h.command("world", world({obstacle("pallet", area({{9, 9}, {10, 9}, {10, 10}}))}));
  EXPECT_TRUE(answer.accepted) << answer.text;
  EXPECT_THAT(answer.text, HasSubstr("world: 1 static, 0 moving obstacles"));
  EXPECT_THAT(inside_both(h), IsEmpty());
}

TEST(SafetyMonitor, AViolationEndsWithItsObstacleAndGoesOnWhileTheWorldKeepsIt) {
  auto h = monitor("{}", {"r1"});
  const auto pallet = world({obstacle("pallet", kPallet)});
  ASSERT_TRUE(h.command("world", pallet).accepted);
  h.feed("r1", robot("r1", 3, 1, kT0));
  h.step();
  EXPECT_THAT(violations(h), SizeIs(1));
  // The same world again (as the coordinator sends it after any change): the same violation.
  EXPECT_THAT(h.command("world", pallet).text, HasSubstr("ended with their obstacles: 0"));
  h.feed("r1", robot("r1", 3, 1, kT0 + 1));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  // Without the pallet, the violation ends; with it back, a robot still inside is a new one.
  EXPECT_EQ(h.command("world", world({})).text,
            "world: 0 static, 0 moving obstacles; violations ended with their obstacles: 1");
  ASSERT_TRUE(h.command("world", pallet).accepted);
  h.feed("r1", robot("r1", 3, 1, kT0 + 2));
  h.step();
  EXPECT_THAT(violations(h), SizeIs(1));
  EXPECT_EQ(kernel(h).count("static_obstacle"), 2u);
}

TEST(SafetyMonitor, ABadWorldIsRefusedWithAReasonAndChangesNothing) {
  auto h = monitor("{}", {"r1", "r2"});
  ASSERT_TRUE(h.command("world", world({obstacle("pallet", kPallet)})).accepted);
  // Each bad world would drop the pallet and add a crate at (10, 10), were it taken.
  const auto crate = obstacle("crate", area({{9, 9}, {11, 9}, {11, 11}, {9, 11}}));
  auto refused = [&](const SwarmObstacle& bad, const std::string& reason) {
    const auto answer = h.command("world", world({crate, bad}));
    EXPECT_FALSE(answer.accepted) << reason;
    EXPECT_THAT(answer.text, HasSubstr(reason));
  };
  refused(obstacle("bow", area({{0, 0}, {1, 1}, {1, 0}, {0, 1}})),
          "world: obstacle 'bow': its shape meets itself at edges 0 and 2 (a polygon must not "
          "intersect itself)");
  refused(obstacle("crate", kUnitSquare),
          "world: obstacle 'crate': obstacles 0 and 1 share the name (names are unique)");
  refused(obstacle("forklift", kUnitSquare,
                   {waypoint(0, 0, 0), waypoint(4, 0, 5 * kSecond), waypoint(8, 0, 10 * kSecond)},
                   10 * kSecond),
          "world: obstacle 'forklift': its loop's first and last points differ: (0.000, 0.000) "
          "and (8.000, 0.000) (a loop ends where it starts)");

  h.feed("r1", robot("r1", 3, 1, kT0));    // in the pallet
  h.feed("r2", robot("r2", 10, 10, kT0));  // in the crate
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->robots(), ElementsAre("r1"));
  EXPECT_THAT(v[0]->detail(), HasSubstr("static obstacle 'pallet'"));
}

// --- (4) jobs ---

TEST(SafetyMonitor, AJobWorkedAtItsPlaceIsQuietAwayFromItReported) {
  auto h = monitor("{}", {"r1"});
  auto job = [&](double x, Stamp t) {
    return working(robot("r1", x, 5, t), "J1", 5, 5, kT0 + 10 * kSecond, kT0 + 20 * kSecond, kT0,
                   kT0 + 60 * kSecond);
  };
  h.feed("r1", job(5.04, kT0 + 11 * kSecond));  // 4 cm off: within 5 cm
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  h.feed("r1", job(5.1, kT0 + 12 * kSecond));
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_EQ(v[0]->kind(), "job");
  EXPECT_EQ(v[0]->job(), "J1");
  EXPECT_THAT(v[0]->robots(), ElementsAre("r1"));
  EXPECT_THAT(v[0]->detail(), HasSubstr("r1 works job J1 at (5.100, 5.000), 0.100 m from the "
                                        "job's place (5.000, 5.000), farther than the job "
                                        "tolerance 0.05 m"));

  auto loose = monitor("{job_tolerance: 0.2}", {"r1"});
  loose.feed("r1", job(5.1, kT0 + 12 * kSecond));
  loose.step();
  EXPECT_THAT(violations(loose), IsEmpty());
}

TEST(SafetyMonitor, AJobWorkedAfterItsWindowIsReported) {
  auto h = monitor("{}", {"r1"});
  // A (faulty) plan: its own time [50 s, 70 s] runs past the job's latest finish at 60 s.
  auto job = [&](Stamp t) {
    return working(robot("r1", 5, 5, t), "J1", 5, 5, kT0 + 50 * kSecond, kT0 + 70 * kSecond, kT0,
                   kT0 + 60 * kSecond);
  };
  h.feed("r1", job(kT0 + 60 * kSecond));  // the latest finish itself: still in time
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  h.feed("r1", job(kT0 + 62 * kSecond));
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_EQ(v[0]->kind(), "job");
  EXPECT_THAT(v[0]->detail(), HasSubstr("2.000 s after the job's latest finish"));
  EXPECT_THAT(v[0]->detail(), Not(HasSubstr("its own end")));
}

TEST(SafetyMonitor, AJobWorkedOutsideItsOwnStartAndEndIsReported) {
  auto h = monitor("{}", {"r1"});
  auto job = [&](Stamp t) {
    return working(robot("r1", 5, 5, t), "J1", 5, 5, kT0 + 10 * kSecond, kT0 + 20 * kSecond, kT0,
                   kT0 + 60 * kSecond);
  };
  h.feed("r1", job(kT0 + 10 * kSecond));
  h.feed("r1", job(kT0 + 20 * kSecond));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  h.feed("r1", job(kT0 + 21 * kSecond));
  h.step();
  auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->detail(), HasSubstr("1.000 s after its own end"));

  auto early = monitor("{}", {"r1"});
  early.feed("r1", job(kT0 + 9 * kSecond));
  early.step();
  v = violations(early);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->detail(), HasSubstr("1.000 s before its own start"));
}

TEST(SafetyMonitor, ARobotWithoutAJobIsNotCheckedForOneAndAJobDroppedEndsItsViolation) {
  auto h = monitor("{}", {"r1"});
  h.feed("r1", robot("r1", 9, 9, kT0));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());
  h.feed("r1", working(robot("r1", 9, 9, kT0 + kSecond), "J1", 5, 5, 0, 0, 0, 0));
  h.step();
  EXPECT_THAT(violations(h), SizeIs(1));
  h.feed("r1", robot("r1", 9, 9, kT0 + 2 * kSecond));  // done with J1
  // J1 again, still away: a new violation.
  h.feed("r1", working(robot("r1", 9, 9, kT0 + 3 * kSecond), "J1", 5, 5, 0, 0, 0, 0));
  h.step();
  EXPECT_THAT(violations(h), SizeIs(1));
  EXPECT_EQ(kernel(h).count("job"), 2u);
}

// --- reporting ---

TEST(SafetyMonitor, AContinuingViolationIsReportedOnceAndAgainAfterItHealed) {
  auto h = monitor("{}", {"r1", "r2", "r3"});
  Stamp t = kT0;
  auto pair = [&](double gap) {
    t += kSecond / 10;
    h.feed("r1", robot("r1", 0, 0, t));
    h.feed("r2", robot("r2", gap, 0, t));
    h.feed("r3", robot("r3", 0, 5, t));
    h.step();
    return violations(h);
  };
  EXPECT_THAT(pair(0.3), SizeIs(1));  // starts
  EXPECT_THAT(pair(0.3), IsEmpty());  // goes on
  EXPECT_THAT(pair(0.2), IsEmpty());
  EXPECT_THAT(pair(0.5), IsEmpty());  // ends
  const auto again = pair(0.35);      // starts anew
  ASSERT_THAT(again, SizeIs(1));
  EXPECT_EQ(again[0]->count(), 2u);
  EXPECT_THAT(pair(0.35), IsEmpty());

  // Another pair is another violation, while the first goes on.
  t += kSecond / 10;
  h.feed("r3", robot("r3", -0.1, 0.3, t));
  h.step();
  const auto other = violations(h);
  ASSERT_THAT(other, SizeIs(1));
  EXPECT_THAT(other[0]->robots(), ElementsAre("r1", "r3"));
  EXPECT_EQ(other[0]->count(), 3u);
  EXPECT_EQ(kernel(h).count("distance"), 3u);
  EXPECT_EQ(kernel(h).total(), 3u);
}

TEST(SafetyMonitor, ALateStateCanStartAViolationButNotEndOne) {
  constexpr Stamp kTenth = kSecond / 10;
  auto h = monitor();
  h.feed("r1", robot("r1", 0, 0, kT0 + 3 * kTenth));
  h.feed("r2", robot("r2", 0.3, 0, kT0 + 3 * kTenth));
  h.step();
  EXPECT_THAT(violations(h), SizeIs(1));
  // r1's state of 0.2 s earlier, far from r2 then, arrives late: the violation goes on.
  h.feed("r1", moving(robot("r1", -1, 0, kT0 + kTenth), 5, 0));
  h.step();
  h.feed("r1", robot("r1", 0, 0, kT0 + 4 * kTenth));
  h.step();
  EXPECT_THAT(violations(h), IsEmpty());

  // The newest states are clear of each other; r2's late state shows it on r1 0.2 s earlier.
  auto late = monitor();
  late.feed("r1", robot("r1", 0, 0, kT0 + 3 * kTenth));
  late.feed("r2", robot("r2", 1, 0, kT0 + 3 * kTenth));
  late.step();
  EXPECT_THAT(violations(late), IsEmpty());
  late.feed("r2", moving(robot("r2", 0.3, 0, kT0 + kTenth), 3.5, 0));
  late.step();
  EXPECT_THAT(violations(late), SizeIs(1));
}

TEST(SafetyMonitor, CountsAreKeptPerKindAndTheCuesCarryTheRunningTotal) {
  auto h = monitor(
      "{static_obstacles: '[[[10, 0], [11, 0], [11, 1], [10, 1]]]', moving_obstacles: '[{shape: "
      "[[0, 0], [1, 0], [1, 1], [0, 1]], loop: [[20, 0, 0], [20, 0, 10]]}]'}",
      {"r1", "r2", "r3", "r4"});
  h.feed("r1", robot("r1", 0, 0, kT0));
  h.feed("r2", robot("r2", 0, 0.1, kT0));         // on r1
  h.feed("r3", robot("r3", 10.5, 0.5, kT0));      // in the static obstacle
  h.feed("r4", robot("r4", 20.5, 0.5, kT0 + 1));  // in the moving one
  h.feed("r4", working(robot("r4", 30, 0, kT0 + 2), "J", 0, 0, 0, 0, 0, 0));  // not at J
  h.step();
  const auto v = violations(h);
  ASSERT_THAT(v, SizeIs(4));
  std::vector<std::string> kinds;
  for (std::size_t i = 0; i < v.size(); ++i) {
    kinds.push_back(v[i]->kind());
    EXPECT_EQ(v[i]->count(), i + 1);
  }
  EXPECT_THAT(kinds, ElementsAre("distance", "static_obstacle", "moving_obstacle", "job"));
  for (const auto* kind : SafetyMonitor::kKinds) EXPECT_EQ(kernel(h).count(kind), 1u) << kind;
  EXPECT_EQ(kernel(h).total(), 4u);
}

// --- stub mode, configuration ---

TEST(SafetyMonitor, StubModeMakesUpAViolationAtMostOnceASecondAndChecksNothing) {
  auto h = monitor();
  h.feed("r1", robot("r1", 0, 0, kT0));
  h.feed("r2", robot("r2", 0, 0, kT0));  // on each other
  h.step_stub();
  auto v = violations(h);
  ASSERT_THAT(v, SizeIs(1));
  EXPECT_THAT(v[0]->detail(), HasSubstr("stub mode: made up, nothing was checked"));
  h.advance(std::chrono::milliseconds(500));
  h.step_stub();
  EXPECT_THAT(violations(h), IsEmpty());
  h.advance(std::chrono::milliseconds(500));
  h.step_stub();
  EXPECT_THAT(violations(h), SizeIs(1));
  EXPECT_EQ(kernel(h).total(), 0u);
  h.step();  // what arrived in stub mode was not checked, and is not checked now
  EXPECT_THAT(violations(h), IsEmpty());
}

TEST(SafetyMonitor, RobotsAreTheWiredInputsAndThoseNamedInParameterInputs) {
  auto h = monitor("{inputs: 'r3'}", {"r1", "r2"});
  std::vector<std::string> names;
  for (const auto& in : h.instance().ports().inputs) names.push_back(in->name());
  EXPECT_THAT(names, ElementsAre("r1", "r2", "r3"));
  h.feed("r3", robot("r3", 0, 0, kT0));
  h.feed("r1", robot("r1", 0.1, 0, kT0));
  h.step();
  EXPECT_THAT(violations(h), SizeIs(1));
}

TEST(SafetyMonitor, BadParametersAreRefusedNamingTheRule) {
  auto refused = [](const std::string& params, const std::string& message) {
    EXPECT_THAT([&] { monitor(params); }, ThrowsMessage<std::invalid_argument>(HasSubstr(message)))
        << params;
  };
  refused("{static_obstacles: '[[[0, 0], [1, 0]]]'}",
          "safety_monitor: parameter 'static_obstacles': obstacle 0 must be a list of at least 3 "
          "vertices [x, y]");
  refused("{static_obstacles: '[[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 0], [1, x]]]'}",
          "obstacle 1: vertex 2 is not [x, y] of finite numbers (m)");
  refused("{static_obstacles: '[[[0, 0], [1, 1], [2, 2]]]'}", "obstacle 0 has no area");
  refused("{static_obstacles: '[[[0, 0]'}", "parameter 'static_obstacles': not YAML");
  refused(
      "{moving_obstacles: '[{shape: [[0, 0], [1, 0], [0, 1]], loop: [[0, 0, 0], [1, 0, "
      "5]]}]'}",
      "parameter 'moving_obstacles': obstacle 0: the loop's first and last points differ: "
      "(0.000, 0.000) and (1.000, 0.000) (a loop ends where it starts)");
  refused(
      "{moving_obstacles: '[{shape: [[0, 0], [1, 0], [0, 1]], loop: [[0, 0, 1], [0, 0, "
      "5]]}]'}",
      "obstacle 0: the loop starts at t = 0, not 1");
  refused(
      "{moving_obstacles: '[{shape: [[0, 0], [1, 0], [0, 1]], loop: [[0, 0, 0], [1, 0, 6], "
      "[0, 0, 5]]}]'}",
      "obstacle 0: loop point 2 goes back in time (5 < 6)");
  refused(
      "{moving_obstacles: '[{shape: [[0, 0], [1, 0], [0, 1]], loop: [[0, 0, 0], [0, 0, "
      "0]]}]'}",
      "obstacle 0: the loop's period (its last t) must be > 0");
  refused("{moving_obstacles: '[{shape: [[0, 0], [1, 0], [0, 1]], path: []}]'}",
          "obstacle 0: unknown key 'path' (it has shape and loop)");
  refused("{inputs: 'r1 r2'}", "parameter 'inputs': 'r1 r2' is not an input name");
  EXPECT_THAT([] { KernelHarness h("safety_monitor", YAML::Load("{}")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr(
                  "safety_monitor: no robots to watch: wire one input per robot in the kernel's "
                  "inputs: (e.g. inputs: { r1: r1/state, r2: r2/state }) or name them in "
                  "parameter 'inputs'")));
}

// The example of modules/swarm_monitor/README.md (tests/docs checks that it is this text).
constexpr const char* kReadmeExample = R"(  - name: monitor
    kernels:
      - type: safety_monitor
        name: safety
        params:
          static_obstacles: '[ [[2, 0], [4, 0], [4, 2], [2, 2]] ]'
          moving_obstacles: >-
            [ {shape: [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]],
            loop: [[0, 4, 0], [8, 4, 10], [0, 4, 20]]} ]
          distance_tolerance: 0.001
          job_tolerance: 0.05
          max_extrapolation: 500ms
        inputs: { r1: r1/state, r2: r2/state, r3: r3/state }
    mode: { continuous: 20ms }
)";

TEST(SafetyMonitor, TheReadmeExampleBuildsAndWatchesItsObstacles) {
  const auto module = YAML::Load(kReadmeExample)[0];
  const auto spec = module["kernels"][0];
  std::map<std::string, InputOverrides> inputs;
  for (const auto& kv : spec["inputs"]) inputs[kv.first.Scalar()] = {};
  KernelHarness h(spec["type"].Scalar(), spec["params"], spec["name"].Scalar(), inputs);
  h.feed("r1", robot("r1", 3, 1, kT0));    // in the static obstacle
  h.feed("r2", robot("r2", 0, 4, kT0));    // under the moving one at loop time 0
  h.feed("r3", robot("r3", 10, 10, kT0));  // clear
  h.step();
  std::vector<std::string> kinds;
  for (const auto& v : violations(h)) kinds.push_back(v->kind() + " " + v->robots().at(0));
  EXPECT_THAT(kinds, ElementsAre("static_obstacle r1", "moving_obstacle r2"));
}

}  // namespace
}  // namespace oscar::modules
