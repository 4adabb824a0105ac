#include "monitor_obstacles.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar::modules::safety {
namespace {

// Seconds from `from_ns` to `to_ns` (to_ns >= from_ns). The difference is taken in unsigned
// arithmetic: it cannot overflow for any two Unix times, and Unix times as doubles would lose
// sub-microsecond precision.
double elapsed_s(std::int64_t from_ns, std::int64_t to_ns) {
  return static_cast<double>(static_cast<std::uint64_t>(to_ns) -
                             static_cast<std::uint64_t>(from_ns)) *
         1e-9;
}

std::invalid_argument world_error(const std::string& what, const std::string& rule) {
  return std::invalid_argument(fmt::format("world: {}: {}", what, rule));
}

Polygon shape_of(const std::string& what, const SwarmArea& area) {
  if (area.x().size() != area.y().size()) {
    throw world_error(what, fmt::format("its shape has {} x and {} y (one of each per vertex)",
                                        area.x().size(), area.y().size()));
  }
  if (area.x().size() < 3) {
    throw world_error(
        what, fmt::format("its shape has {} vertices, a polygon at least 3", area.x().size()));
  }
  Polygon polygon;
  for (std::size_t i = 0; i < area.x().size(); ++i) {
    const Point p{area.x()[i], area.y()[i]};
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      throw world_error(what, fmt::format("vertex {} of its shape is not finite", i));
    }
    polygon.push_back(p);
  }
  // A polygon meeting itself has no well-defined inside: the checks would be meaningless.
  if (const auto edges = self_contact(polygon)) {
    throw world_error(what, fmt::format("its shape meets itself at edges {} and {} (a polygon "
                                        "must not intersect itself)",
                                        edges->first, edges->second));
  }
  return polygon;
}

MovingObstacle moving_of(const std::string& what, const SwarmObstacle& o) {
  MovingObstacle m;
  m.name = o.name();
  m.shape = shape_of(what, o.shape());
  m.since_ns = o.since_ns();
  const auto& path = o.path();
  for (std::size_t k = 0; k < path.size(); ++k) {
    if (!std::isfinite(path[k].x()) || !std::isfinite(path[k].y())) {
      throw world_error(what, fmt::format("path point {} is not finite", k));
    }
    if (k > 0 && path[k].t_ns() < path[k - 1].t_ns()) {
      throw world_error(what, fmt::format("path point {} goes back in time ({} < {} ns)", k,
                                          path[k].t_ns(), path[k - 1].t_ns()));
    }
  }
  const auto& first = path.front();
  const auto& last = path.back();
  if (o.loop_ns() > 0) {
    // The rules of parameter moving_obstacles' loops.
    if (first.t_ns() != 0) {
      throw world_error(what, fmt::format("its loop starts at t_ns 0, not {}", first.t_ns()));
    }
    if (last.t_ns() != o.loop_ns()) {
      throw world_error(what, fmt::format("its loop ends at t_ns {}, not at loop_ns {}",
                                          last.t_ns(), o.loop_ns()));
    }
    if (first.x() != last.x() || first.y() != last.y()) {
      throw world_error(what, fmt::format("its loop's first and last points differ: ({:.3f}, "
                                          "{:.3f}) and ({:.3f}, {:.3f}) (a loop ends where it "
                                          "starts)",
                                          first.x(), first.y(), last.x(), last.y()));
    }
    m.period_ns = o.loop_ns();
  } else {
    m.start_ns = first.t_ns();
    m.end_ns = last.t_ns();
  }
  const std::int64_t origin_ns = m.period_ns > 0 ? 0 : m.start_ns;
  for (const auto& p : path) m.path.push_back({p.x(), p.y(), elapsed_s(origin_ns, p.t_ns())});
  return m;
}

}  // namespace

double MovingObstacle::path_time_s(std::int64_t t_ns) const {
  if (period_ns > 0) return loop_phase_s(t_ns, period_ns);
  return t_ns >= start_ns ? elapsed_s(start_ns, t_ns) : -elapsed_s(t_ns, start_ns);
}

std::optional<Point> MovingObstacle::origin_at(std::int64_t t_ns) const {
  if (t_ns < since_ns) return std::nullopt;
  if (period_ns == 0 && (t_ns < start_ns || t_ns > end_ns)) return std::nullopt;
  return loop_position(path, path_time_s(t_ns));
}

std::string obstacle_label(const std::string& name, std::size_t index) {
  return name.empty() ? std::to_string(index) : fmt::format("'{}'", name);
}

Obstacles obstacles_of(const SwarmWorld& world) {
  Obstacles out;
  std::map<std::string, std::size_t> index_of;  // by name
  for (std::size_t i = 0; i < world.obstacles().size(); ++i) {
    const auto& o = world.obstacles()[i];
    if (o.name().empty()) {
      throw world_error(fmt::format("obstacle {}", i), "it has no name (each needs one)");
    }
    const auto what = fmt::format("obstacle '{}'", o.name());
    if (const auto [it, added] = index_of.emplace(o.name(), i); !added) {
      throw world_error(what, fmt::format("obstacles {} and {} share the name (names are unique)",
                                          it->second, i));
    }
    if (o.loop_ns() < 0) {
      throw world_error(
          what, fmt::format("loop_ns is {} (0: no loop, > 0: the loop's period)", o.loop_ns()));
    }
    if (o.since_ns() < 0) {
      throw world_error(what, fmt::format("since_ns is {} (0: from the start)", o.since_ns()));
    }
    if (o.path().empty()) {
      if (o.loop_ns() != 0) {
        throw world_error(what, fmt::format("loop_ns is {} but it has no path (a static obstacle "
                                            "has loop_ns 0)",
                                            o.loop_ns()));
      }
      out.static_obstacles.push_back({o.name(), shape_of(what, o.shape()), o.since_ns()});
    } else {
      out.moving_obstacles.push_back(moving_of(what, o));
    }
  }
  return out;
}

}  // namespace oscar::modules::safety
