#include "live_world.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <stdexcept>

namespace oscar::coordinator {

namespace {

constexpr std::size_t kMaxName = 128;

std::string what(const SwarmObstacle& o) { return fmt::format("obstacle '{}'", o.name()); }

void check_path(const SwarmObstacle& o) {
  const auto& path = o.path();
  if (o.loop_ns() < 0) {
    throw std::invalid_argument(fmt::format("{}: loop_ns {} is negative", what(o), o.loop_ns()));
  }
  if (path.empty()) {
    if (o.loop_ns() > 0) throw std::invalid_argument(what(o) + ": a loop needs a path");
    return;  // it stands
  }
  if (path.size() < 2) {
    throw std::invalid_argument(what(o) + ": a moving obstacle's path has at least 2 points");
  }
  for (std::size_t k = 1; k < path.size(); ++k) {
    if (path[k].t_ns() < path[k - 1].t_ns()) {
      throw std::invalid_argument(fmt::format("{}: path point {} goes back in time", what(o), k));
    }
  }
  if (o.loop_ns() == 0) {
    if (path.back().t_ns() == path.front().t_ns()) {
      throw std::invalid_argument(what(o) + ": its path lasts no time");
    }
    return;
  }
  const auto& first = path.front();
  const auto& last = path.back();
  if (first.t_ns() != 0 || last.t_ns() != o.loop_ns()) {
    throw std::invalid_argument(
        fmt::format("{}: a loop runs from t = 0 to its period {} ns, not from {} to {}", what(o),
                    o.loop_ns(), first.t_ns(), last.t_ns()));
  }
  if (first.x() != last.x() || first.y() != last.y()) {
    throw std::invalid_argument(what(o) + ": a loop ends where it starts");
  }
}

}  // namespace

swarm::Polygon obstacle_shape(const SwarmObstacle& o) {
  const auto& xs = o.shape().x();
  const auto& ys = o.shape().y();
  if (xs.size() != ys.size()) {
    throw std::invalid_argument(
        fmt::format("{} shape: {} x but {} y coordinates", what(o), xs.size(), ys.size()));
  }
  std::vector<swarm::Point> points;
  for (std::size_t i = 0; i < xs.size(); ++i) points.emplace_back(xs[i], ys[i]);
  return swarm::make_polygon(points, what(o) + " shape");
}

void LiveWorld::add(SwarmObstacle o) {
  if (o.name().empty() || o.name().size() > kMaxName) {
    throw std::invalid_argument(fmt::format("an obstacle's name has 1 to {} characters, not {}",
                                            kMaxName, o.name().size()));
  }
  if (std::any_of(obstacles_.begin(), obstacles_.end(),
                  [&](const SwarmObstacle& x) { return x.name() == o.name(); })) {
    throw std::invalid_argument(what(o) + ": the world has one of that name already");
  }
  obstacle_shape(o);
  check_path(o);
  obstacles_.push_back(std::move(o));
}

void LiveWorld::remove(const std::string& name) {
  const auto n =
      std::erase_if(obstacles_, [&](const SwarmObstacle& o) { return o.name() == name; });
  if (n == 0) throw std::invalid_argument(fmt::format("the world has no obstacle '{}'", name));
}

bool LiveWorld::has_loops() const {
  return std::any_of(obstacles_.begin(), obstacles_.end(),
                     [](const SwarmObstacle& o) { return o.loop_ns() > 0; });
}

swarm::World LiveWorld::planned(const swarm_wire::Clock& clock, double from, double to) const {
  swarm::World world;
  for (const auto& o : obstacles_) {
    const swarm::Polygon shape = obstacle_shape(o);
    if (o.path().empty()) {
      world.static_obstacles.push_back(shape);
      continue;
    }
    swarm::Trajectory t;
    if (o.loop_ns() == 0) {
      for (const auto& p : o.path()) t.append({p.x(), p.y(), clock.seconds(p.t_ns())});
    } else {
      // Each round of the loop from the one under way at `from` to the one under way at `to`.
      const std::int64_t period = o.loop_ns();
      const std::int64_t end = clock.ns(to);
      for (std::int64_t round = clock.ns(from) / period * period; round <= end; round += period) {
        for (const auto& p : o.path()) t.append({p.x(), p.y(), clock.seconds(round + p.t_ns())});
      }
    }
    world.dynamic_obstacles.push_back({shape, std::move(t)});
  }
  return world;
}

SwarmWorld LiveWorld::wire() const {
  SwarmWorld w;
  w.obstacles(obstacles_);
  return w;
}

}  // namespace oscar::coordinator
