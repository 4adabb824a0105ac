#include "oscar/swarm/dubins_path_finder.hpp"

#include <gtest/gtest.h>

#include <ompl/base/ScopedState.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "oscar/swarm/scheduler.hpp"
#include "oscar/swarm/spatial_path_finder.hpp"
#include "safe_dubins_state_space.hpp"

namespace oscar::swarm {
namespace {

Polygon square(double x0, double y0, double x1, double y1) {
  return make_polygon({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, "square");
}

TEST(DubinsPathFinderTest, MatchesTheExactPlannerWhereBothApply) {
  // Free space, headings along the line: a Dubins car drives straight.
  DubinsPathFinder dubins({}, {.turning_radius_m = 0.5, .iterations = 500, .resolution_m = 0.1});
  const auto path = dubins.find({0, 0}, {10, 0});
  ASSERT_TRUE(path);
  EXPECT_NEAR(dubins.last_length(), 10, 1e-6);
  EXPECT_NEAR(path_length(*path), 10, 1e-6);
}

// Regression (property test): a leg in -x direction has heading atan2(0, -1) = π, outside OMPL's
// SO2 bounds [-π, π); OMPL aborted on an assertion.
TEST(DubinsPathFinderTest, LegInNegativeXDirectionIsStraight) {
  DubinsPathFinder dubins({}, {.turning_radius_m = 0.5, .iterations = 500, .resolution_m = 0.1});
  const auto path = dubins.find({10, 0}, {0, 0});
  ASSERT_TRUE(path);
  EXPECT_NEAR(path_length(*path), 10, 1e-6);
}

TEST(DubinsPathFinderTest, AroundAnObstacleNoShorterThanExactAndClose) {
  const std::vector<Polygon> obstacles{square(4, -2, 6, 2)};
  SpatialPathFinder exact(obstacles);
  DubinsPathFinder dubins(
      obstacles,
      {.turning_radius_m = 0.5, .iterations = 3000, .restarts = 8, .resolution_m = 0.05});
  const auto e = exact.find({0, 0}, {10, 0});
  const auto d = dubins.find({0, 0}, {10, 0});
  ASSERT_TRUE(e);
  ASSERT_TRUE(d);
  const double le = path_length(*e);
  const double ld = path_length(*d);
  EXPECT_GE(ld, le - 1e-9);  // the exact planner is a lower bound
  EXPECT_LE(ld, 1.35 * le);  // and RRT with shortcutting gets near it
  for (std::size_t i = 1; i < d->size(); ++i) EXPECT_TRUE(exact.visible((*d)[i - 1], (*d)[i]));
  RecordProperty("exact_length", std::to_string(le));
  RecordProperty("dubins_length", std::to_string(ld));
  std::printf("exact %.3f m, dubins (r = 0.5 m) %.3f m\n", le, ld);
}

TEST(DubinsPathFinderTest, NoPathIntoAnObstacle) {
  DubinsPathFinder dubins({square(4, -2, 6, 2)},
                          {.turning_radius_m = 0.5, .iterations = 200, .resolution_m = 0.1});
  EXPECT_FALSE(dubins.find({0, 0}, {5, 0}));
}

// The poses of a Dubins test pair.
struct Pose {
  double x, y, yaw;
};

// Drives from `p` along `amount` radians of a circle of `radius` to the left (side 1) or right
// (side -1), or `amount` radii straight on (side 0).
Pose drive(const Pose& p, int side, double amount, double radius) {
  if (side == 0) {
    return {p.x + amount * radius * std::cos(p.yaw), p.y + amount * radius * std::sin(p.yaw),
            p.yaw};
  }
  const double yaw = p.yaw + side * amount;
  return {p.x + side * radius * (std::sin(yaw) - std::sin(p.yaw)),
          p.y - side * radius * (std::cos(yaw) - std::cos(p.yaw)), yaw};
}

// The Dubins distance between two poses and the pose halfway, as SafeDubinsStateSpace gives them,
// and whether OMPL's motion validator for the space (DubinsMotionValidator) accepts the motion.
struct Evaluated {
  double distance;
  Pose halfway;
  bool motion_valid;
};

Evaluated evaluate(const Pose& a, const Pose& b, double radius) {
  namespace ob = ompl::base;
  auto space = std::make_shared<SafeDubinsStateSpace>(radius);
  ob::RealVectorBounds bounds(2);
  bounds.setLow(-1e5);
  bounds.setHigh(1e5);
  space->setBounds(bounds);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([](const ob::State*) { return true; });
  si->setup();
  ob::ScopedState<ob::SE2StateSpace> s1(space), s2(space), mid(space);
  s1->setXY(a.x, a.y);
  s1->setYaw(a.yaw);
  s2->setXY(b.x, b.y);
  s2->setYaw(b.yaw);
  space->enforceBounds(s1.get());  // headings into OMPL's [-π, π)
  space->enforceBounds(s2.get());
  const double d = space->distance(s1.get(), s2.get());
  space->interpolate(s1.get(), s2.get(), 0.5, mid.get());
  return {d, {mid->getX(), mid->getY(), mid->getYaw()}, si->checkMotion(s1.get(), s2.get())};
}

// Regression (fuzzing DubinsPathFinder::find): RRT asked OMPL 1.5.2 for this pair, a pose heading
// 1e-7 rad past the tangent of the goal's left turning circle. OMPL's LSL word rounded its first
// turn, 2π - 1e-7, to none and then missed the goal by more than its assertion allows:
// "dubinsLSL: Assertion `fabs(p * sin(alpha + t) + ca - cb) < 2 * DUBINS_EPS' failed", SIGABRT.
TEST(SafeDubinsStateSpace, PairThatAbortedOmpl) {
  const Pose a{29.602002781295749, 8.8323076814379515, -1.165653546272055};
  const Pose b{31.468454428809579, 4.4802754894014862, -1.114587906073115};
  const auto e = evaluate(a, b, 0.0013301667365282085);
  const double straight = std::hypot(b.x - a.x, b.y - a.y);
  EXPECT_GE(e.distance, straight);
  EXPECT_LT(e.distance, straight + 0.01);  // a slight turn at the end
  EXPECT_TRUE(std::isfinite(e.halfway.x) && std::isfinite(e.halfway.y));
  EXPECT_TRUE(e.motion_valid);
}

// Pairs built like that one for every word: a first (or last) turn a hair short of a full turn,
// then a long straight part or a loop. OMPL 1.5.2 alone aborts on most of them.
TEST(SafeDubinsStateSpace, NearlyFullTurnsOfEveryWordAreComputed) {
  constexpr double kPi = std::numbers::pi;
  std::mt19937 rng(3);
  auto uni = [&](double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng); };
  const int words[6][3] = {{1, 0, 1}, {-1, 0, -1}, {1, 0, -1}, {-1, 0, 1}, {1, -1, 1}, {-1, 1, -1}};
  for (int i = 0; i < 3000; ++i) {
    const auto& word = words[i % 6];
    const bool loop = word[1] != 0;
    const double radius = std::pow(10, uni(-3, 1));
    const double hair = -std::pow(10, uni(-7.5, -6.3));  // OMPL rounds up to 5e-7 rad
    const double middle = loop ? uni(kPi + 0.1, 2 * kPi - 0.1) : uni(4, 2000);
    const bool last = i % 12 >= 6;  // the hair at the end instead
    const double first = last ? uni(0.1, 2 * kPi - 0.1) : hair;
    const double final = last ? hair : uni(0.1, 2 * kPi - 0.1);
    const Pose a{uni(-100, 100), uni(-100, 100), uni(-kPi, kPi)};
    const Pose b = drive(drive(drive(a, word[0], first, radius), word[1], middle, radius), word[2],
                         final, radius);
    const auto e = evaluate(a, b, radius);
    ASSERT_TRUE(std::isfinite(e.distance)) << "pair " << i;
    ASSERT_GE(e.distance, std::hypot(b.x - a.x, b.y - a.y) - 1e-9) << "pair " << i;
    ASSERT_TRUE(std::isfinite(e.halfway.x) && std::isfinite(e.halfway.y)) << "pair " << i;
    ASSERT_TRUE(e.motion_valid) << "pair " << i;
  }
}

// Regression (fuzzing): this leg, with these settings and seed, aborted in OMPL's dubinsLSL on a
// pair RRT made. It depends on the exact random sequence, so a change to the planner may make it
// pass without the guard; the tests above do not.
TEST(DubinsPathFinderTest, LegThatAbortedOmplIsPlanned) {
  const std::vector<Polygon> wall{square(20, 10, 30, 40)};
  DubinsPathFinder dubins(wall, {.turning_radius_m = 0.0022792493887212198,
                                 .iterations = 300,
                                 .restarts = 2,
                                 .resolution_m = 0.1,
                                 .seed = 1});
  const auto path = dubins.find({4.5671153690979054, 15.295945655379365},
                                {38.748485111440914, 5.5870640990315596});
  ASSERT_TRUE(path);
  SpatialPathFinder exact(wall);
  for (std::size_t k = 1; k < path->size(); ++k) {
    EXPECT_TRUE(exact.visible((*path)[k - 1], (*path)[k])) << "segment " << k;
  }
}

// Legs around a wall with small turning radii make RRT produce such pairs (fuzzing found about one
// abort in a hundred legs before SafeDubinsStateSpace); every leg must end in a path or nullopt.
TEST(DubinsPathFinderTest, LegsAroundAWallWithSmallTurningRadiiNeverAbort) {
  std::mt19937 rng(5);
  auto uni = [&](double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng); };
  const std::vector<Polygon> wall{square(20, 10, 30, 40)};
  SpatialPathFinder exact(wall);
  int found = 0;
  for (int i = 0; i < 150; ++i) {
    DubinsPathFinder dubins(wall, {.turning_radius_m = std::pow(10, uni(-3, -1)),
                                   .iterations = 300,
                                   .restarts = 2,
                                   .resolution_m = 0.1});
    const auto path = dubins.find({uni(0, 15), uni(0, 50)}, {uni(35, 50), uni(0, 50)});
    if (!path) continue;
    ++found;
    for (std::size_t k = 1; k < path->size(); ++k) {
      ASSERT_TRUE(exact.visible((*path)[k - 1], (*path)[k])) << "leg " << i;
    }
  }
  EXPECT_GT(found, 100);
}

TEST(DubinsPathFinderTest, RejectsSettingsOmplCannotPlanWith) {
  EXPECT_THROW(DubinsPathFinder({}, {.turning_radius_m = 0}), std::invalid_argument);
  EXPECT_THROW(DubinsPathFinder({}, {.turning_radius_m = NAN}), std::invalid_argument);
  EXPECT_THROW(DubinsPathFinder({}, {.resolution_m = 0}), std::invalid_argument);
  EXPECT_THROW(DubinsPathFinder({}, {.iterations = 0}), std::invalid_argument);
  EXPECT_THROW(DubinsPathFinder({}, {.restarts = 0}), std::invalid_argument);
}

TEST(DubinsPathFinderTest, LegsOmplCannotPlanAreNotFound) {
  DubinsPathFinder dubins({}, {.turning_radius_m = 0.5});
  EXPECT_FALSE(dubins.find({NAN, 0}, {10, 0}));
  EXPECT_FALSE(dubins.find({0, 0}, {INFINITY, 0}));
  // 1e8 turning radii between start and goal: beyond what OMPL's arithmetic is trusted with.
  DubinsPathFinder tiny({}, {.turning_radius_m = 1e-7});
  EXPECT_FALSE(tiny.find({0, 0}, {10, 0}));
}

// True if both legs were found and are the same polyline, to the bit.
bool same(const std::optional<std::vector<Point>>& a, const std::optional<std::vector<Point>>& b) {
  return a && b &&
         std::equal(a->begin(), a->end(), b->begin(), b->end(), [](const Point& p, const Point& q) {
           return p.x() == q.x() && p.y() == q.y();
         });
}

// Regression: OMPL's generators were seeded once per process, so a leg that needs RRT planned
// differently depending on what was planned before it.
TEST(DubinsPathFinderTest, SameLegPlansTheSameWhateverWasPlannedBefore) {
  const std::vector<Polygon> obstacles{square(4, -2, 6, 2)};
  const DubinsPathFinder::Settings settings{
      .turning_radius_m = 0.5, .iterations = 1000, .restarts = 4, .seed = 7};
  DubinsPathFinder dubins(obstacles, settings);
  const auto first = dubins.find({0, 0}, {10, 0});
  ASSERT_TRUE(first);
  EXPECT_TRUE(dubins.find({0, 1}, {10, -1}));  // other legs, other finders in between
  EXPECT_TRUE(DubinsPathFinder(obstacles, settings).find({0, -1}, {10, 1}));
  EXPECT_TRUE(same(dubins.find({0, 0}, {10, 0}), first));
  EXPECT_TRUE(same(DubinsPathFinder(obstacles, settings).find({0, 0}, {10, 0}), first));
  auto reseeded = settings;
  reseeded.seed = 8;
  EXPECT_FALSE(same(DubinsPathFinder(obstacles, reseeded).find({0, 0}, {10, 0}), first));
}

// The same through the scheduler: SchedulerSettings::seed seeds the Dubins planner.
TEST(DubinsPathFinderTest, SchedulerPlansTheSameProblemTheSameEveryTime) {
  World w;
  w.static_obstacles.push_back(square(4, -2, 6, 2));
  auto plan = [&](unsigned seed) {
    Scheduler s(w, {.seed = seed});
    s.add_node({"car", 0.2, 1, 0, 0, 0, 0.5});
    const auto r = s.schedule(JobSpec{"J", square(9, -1, 11, 1), 0, 100, 5});
    EXPECT_TRUE(r.ok) << r.reason;
    s.commit(r.transaction);
    return s.trajectory("car").points();
  };
  auto same_trajectory = [](const std::vector<Waypoint>& a, const std::vector<Waypoint>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& p, const auto& q) {
      return p.x == q.x && p.y == q.y && p.t == q.t;
    });
  };
  const auto first = plan(3);
  const auto other = plan(4);  // other planning in between
  EXPECT_TRUE(same_trajectory(plan(3), first));
  EXPECT_FALSE(same_trajectory(other, first));
}

TEST(DubinsPathFinderTest, SchedulerUsesItForNodesWithATurningRadius) {
  World w;
  w.static_obstacles.push_back(square(4, -2, 6, 2));
  Scheduler s(w, {});
  s.add_node({"car", 0.2, 1, 0, 0, 0, 0.5});
  const auto r = s.schedule(JobSpec{"J", square(9, -1, 11, 1), 0, 100, 5});
  ASSERT_TRUE(r.ok) << r.reason;
  s.commit(r.transaction);
  const auto& t = s.trajectory("car").points();
  EXPECT_GT(t.size(), 10u);  // a sampled curve, not the visibility graph's 4 corners
  SpatialPathFinder wall({inflate(square(4, -2, 6, 2), 0.2)});
  for (std::size_t i = 1; i < t.size(); ++i) {
    EXPECT_TRUE(wall.visible({t[i - 1].x, t[i - 1].y}, {t[i].x, t[i].y})) << "segment " << i;
  }
}

}  // namespace
}  // namespace oscar::swarm
