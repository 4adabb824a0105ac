#include "oscar/swarm/dubins_path_finder.hpp"

#include <ompl/base/ScopedState.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SO2StateSpace.h>
#include <ompl/base/terminationconditions/IterationTerminationCondition.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/util/Console.h>

#include <fmt/format.h>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <stdexcept>
#include <utility>

#include "safe_dubins_state_space.hpp"

namespace oscar::swarm {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

// OMPL's Dubins arithmetic keeps its tolerance over spans up to about 1e9 turning radii; the
// planner stays well below (a kilometre for a turning radius of a millimetre).
constexpr double kMaxSpanInRadii = 1e6;

bool finite(const Point& p) { return std::isfinite(p.x()) && std::isfinite(p.y()); }

// An OMPL class whose random generator (the protected member rng_ of planners, state samplers and
// the path simplifier) starts from `seed` instead of from OMPL's process-wide sequence of seeds.
template <class Base>
class Seeded : public Base {
 public:
  template <class... Args>
  explicit Seeded(std::uint_fast32_t seed, Args&&... args) : Base(std::forward<Args>(args)...) {
    this->rng_.setLocalSeed(seed);
  }
};

// The generator of every seed in one query, from the settings' seed and the leg's ends: a leg
// plans the same whatever the process planned before.
std::shared_ptr<std::mt19937> query_seeds(unsigned seed, const Point& from, const Point& to) {
  std::vector<std::uint32_t> words{seed};
  for (const double v : {from.x(), from.y(), to.x(), to.y()}) {
    const auto bits = std::bit_cast<std::uint64_t>(v);
    words.push_back(static_cast<std::uint32_t>(bits));
    words.push_back(static_cast<std::uint32_t>(bits >> 32));
  }
  std::seed_seq sequence(words.begin(), words.end());
  return std::make_shared<std::mt19937>(sequence);
}

// Gives every state sampler of the Dubins space (RRT allocates one per attempt) a generator seeded
// from `seeds`: the space's default sampler samples position and heading with its subspaces'.
void seed_samplers(ob::DubinsStateSpace& space, const std::shared_ptr<std::mt19937>& seeds) {
  space.getSubspace(0)->setStateSamplerAllocator([seeds](const ob::StateSpace* s) {
    return std::make_shared<Seeded<ob::RealVectorStateSampler>>((*seeds)(), s);
  });
  space.getSubspace(1)->setStateSamplerAllocator([seeds](const ob::StateSpace* s) {
    return std::make_shared<Seeded<ob::SO2StateSampler>>((*seeds)(), s);
  });
}

// The region RRT samples: start, goal and every obstacle, plus room to turn.
ob::RealVectorBounds planning_bounds(const Point& from, const Point& to,
                                     const std::vector<Polygon>& obstacles, double turning_radius) {
  double x0 = std::min(from.x(), to.x()), x1 = std::max(from.x(), to.x());
  double y0 = std::min(from.y(), to.y()), y1 = std::max(from.y(), to.y());
  for (const auto& p : obstacles) {
    for (const auto& v : vertices(p)) {
      x0 = std::min(x0, v.x());
      x1 = std::max(x1, v.x());
      y0 = std::min(y0, v.y());
      y1 = std::max(y1, v.y());
    }
  }
  const double margin = 4 * turning_radius + 1;
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0, x0 - margin);
  bounds.setHigh(0, x1 + margin);
  bounds.setLow(1, y0 - margin);
  bounds.setHigh(1, y1 + margin);
  return bounds;
}

double diagonal(const ob::RealVectorBounds& b) {
  return std::hypot(b.high[0] - b.low[0], b.high[1] - b.low[1]);
}

// The Dubins path of the leg: the direct curve if free, else the shortest of the RRT attempts.
std::optional<og::PathGeometric> plan(const Point& from, const Point& to,
                                      const ob::RealVectorBounds& bounds,
                                      const SpatialPathFinder& exact,
                                      const DubinsPathFinder::Settings& settings) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  const auto seeds = query_seeds(settings.seed, from, to);
  auto space = std::make_shared<SafeDubinsStateSpace>(settings.turning_radius_m);
  space->setBounds(bounds);
  seed_samplers(*space, seeds);
  og::SimpleSetup setup(space);
  setup.setStateValidityChecker([&exact](const ob::State* s) {
    const auto* st = s->as<ob::SE2StateSpace::StateType>();
    return exact.is_free(Point(st->getX(), st->getY()));
  });
  setup.getSpaceInformation()->setStateValidityCheckingResolution(
      std::min(0.01, settings.resolution_m / 10));
  const double heading = std::atan2(to.y() - from.y(), to.x() - from.x());
  ob::ScopedState<ob::SE2StateSpace> start(space), goal(space);
  start->setXY(from.x(), from.y());
  start->setYaw(heading);
  goal->setXY(to.x(), to.y());
  goal->setYaw(heading);
  // atan2 gives π for a leg in -x direction, but OMPL's SO2 bounds are [-π, π): unnormalised, its
  // distance asserts (found by the property test).
  space->enforceBounds(start.get());
  space->enforceBounds(goal.get());
  setup.setStartAndGoalStates(start, goal, 1e-6);
  setup.setup();
  const auto si = setup.getSpaceInformation();
  og::PathGeometric path(si);
  if (si->checkMotion(start.get(), goal.get())) {
    // The Dubins curve between the two poses is free: it is the shortest one.
    path.append(start.get());
    path.append(goal.get());
    return path;
  }
  // RRT* needs a symmetric metric, which Dubins is not: plain RRT, restarted a few times, each
  // result shortcut, the shortest kept.
  setup.setPlanner(std::make_shared<Seeded<og::RRT>>((*seeds)(), si));
  Seeded<og::PathSimplifier> simplifier((*seeds)(), si, setup.getGoal());
  bool found = false;
  for (int attempt = 0; attempt < settings.restarts; ++attempt) {
    setup.clear();
    ob::IterationTerminationCondition iterations(static_cast<unsigned>(settings.iterations));
    if (setup.solve(iterations) != ob::PlannerStatus::EXACT_SOLUTION) continue;
    og::PathGeometric candidate = setup.getSolutionPath();
    simplifier.simplifyMax(candidate);  // shortcutting keeps the validity checks
    if (!found || candidate.length() < path.length()) path = candidate;
    found = true;
  }
  if (!found) return std::nullopt;
  return path;
}

// The path sampled every `resolution` metres from `from` to `to`, or nullopt if a chord cuts an
// obstacle.
std::optional<std::vector<Point>> sampled(og::PathGeometric path, const Point& from,
                                          const Point& to, double resolution,
                                          const SpatialPathFinder& exact) {
  path.interpolate(static_cast<unsigned>(std::ceil(path.length() / resolution)) + 2);
  std::vector<Point> result;
  for (std::size_t i = 0; i < path.getStateCount(); ++i) {
    const auto* st = path.getState(i)->as<ob::SE2StateSpace::StateType>();
    const Point p(st->getX(), st->getY());
    if (!result.empty() && distance(result.back(), p) <= kEpsilon) continue;
    if (!result.empty() && !exact.visible(result.back(), p)) return std::nullopt;
    result.push_back(p);
  }
  result.front() = from;
  result.back() = to;
  return result;
}

void check_settings(const DubinsPathFinder::Settings& s) {
  auto positive = [](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0) {
      throw std::invalid_argument(
          fmt::format("DubinsPathFinder: {} = {}: must be finite and > 0", name, v));
    }
  };
  positive(s.turning_radius_m, "turning_radius_m");
  positive(s.resolution_m, "resolution_m");
  if (s.iterations < 1 || s.restarts < 1) {
    throw std::invalid_argument(
        fmt::format("DubinsPathFinder: iterations = {}, restarts = {}: both must be >= 1",
                    s.iterations, s.restarts));
  }
}

}  // namespace

DubinsPathFinder::DubinsPathFinder(std::vector<Polygon> obstacles, Settings settings)
    : exact_(obstacles), obstacles_(std::move(obstacles)), settings_(settings) {
  check_settings(settings_);
}

std::optional<std::vector<Point>> DubinsPathFinder::find(const Point& from, const Point& to) const {
  if (!finite(from) || !finite(to)) return std::nullopt;
  if (!exact_.is_free(from) || !exact_.is_free(to)) return std::nullopt;
  if (distance(from, to) <= kEpsilon) return std::vector<Point>{from, to};
  const auto bounds = planning_bounds(from, to, obstacles_, settings_.turning_radius_m);
  if (diagonal(bounds) > kMaxSpanInRadii * settings_.turning_radius_m) return std::nullopt;
  try {
    const auto path = plan(from, to, bounds, exact_, settings_);
    if (!path) return std::nullopt;
    last_length_ = path->length();
    return sampled(*path, from, to, settings_.resolution_m, exact_);
  } catch (const UnsafeDubinsPair&) {
    return std::nullopt;  // OMPL cannot compute some Dubins curve near the leg
  }
}

}  // namespace oscar::swarm
