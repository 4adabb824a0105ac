#include "oscar/swarm/dubins_path_finder.hpp"

#include <ompl/base/ScopedState.h>
#include <ompl/base/spaces/DubinsStateSpace.h>
#include <ompl/base/terminationconditions/IterationTerminationCondition.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <cmath>

namespace oscar::swarm {

namespace ob = ompl::base;
namespace og = ompl::geometric;

DubinsPathFinder::DubinsPathFinder(std::vector<Polygon> obstacles, Settings settings)
    : exact_(obstacles), obstacles_(std::move(obstacles)), settings_(settings) {}

std::optional<std::vector<Point>> DubinsPathFinder::find(const Point& from, const Point& to) const {
  if (!exact_.is_free(from) || !exact_.is_free(to)) return std::nullopt;
  if (distance(from, to) <= kEpsilon) return std::vector<Point>{from, to};
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  auto space = std::make_shared<ob::DubinsStateSpace>(settings_.turning_radius_m);
  // Bounds: everything of interest plus room to turn.
  double x0 = std::min(from.x(), to.x()), x1 = std::max(from.x(), to.x());
  double y0 = std::min(from.y(), to.y()), y1 = std::max(from.y(), to.y());
  for (const auto& p : obstacles_) {
    for (const auto& v : vertices(p)) {
      x0 = std::min(x0, v.x());
      x1 = std::max(x1, v.x());
      y0 = std::min(y0, v.y());
      y1 = std::max(y1, v.y());
    }
  }
  const double margin = 4 * settings_.turning_radius_m + 1;
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0, x0 - margin);
  bounds.setHigh(0, x1 + margin);
  bounds.setLow(1, y0 - margin);
  bounds.setHigh(1, y1 + margin);
  space->setBounds(bounds);
  og::SimpleSetup setup(space);
  setup.setStateValidityChecker([this](const ob::State* s) {
    const auto* st = s->as<ob::SE2StateSpace::StateType>();
    return exact_.is_free(Point(st->getX(), st->getY()));
  });
  setup.getSpaceInformation()->setStateValidityCheckingResolution(
      std::min(0.01, settings_.resolution_m / 10));
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
  } else {
    // RRT* needs a symmetric metric, which Dubins is not: plain RRT, restarted a few times,
    // each result shortcut, the shortest kept.
    setup.setPlanner(std::make_shared<og::RRT>(si));
    bool found = false;
    for (int attempt = 0; attempt < settings_.restarts; ++attempt) {
      setup.clear();
      ob::IterationTerminationCondition iterations(static_cast<unsigned>(settings_.iterations));
      if (setup.solve(iterations) != ob::PlannerStatus::EXACT_SOLUTION) continue;
      setup.simplifySolution();  // shortcutting keeps the validity checks
      const og::PathGeometric& candidate = setup.getSolutionPath();
      if (!found || candidate.length() < path.length()) path = candidate;
      found = true;
    }
    if (!found) return std::nullopt;
  }
  last_length_ = path.length();
  path.interpolate(static_cast<unsigned>(std::ceil(path.length() / settings_.resolution_m)) + 2);
  std::vector<Point> result;
  for (std::size_t i = 0; i < path.getStateCount(); ++i) {
    const auto* st = path.getState(i)->as<ob::SE2StateSpace::StateType>();
    const Point p(st->getX(), st->getY());
    if (!result.empty() && distance(result.back(), p) <= kEpsilon) continue;
    if (!result.empty() && !exact_.visible(result.back(), p)) return std::nullopt;  // a chord cuts
    result.push_back(p);
  }
  result.front() = from;
  result.back() = to;
  return result;
}

}  // namespace oscar::swarm
