// oscar swarm snapshot -o FILE.svg: the running swarm drawn now (docs/swarm.md).
#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "coordinator_topic.hpp"
#include "live.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"
#include "oscar/swarm/geometry.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "svg.hpp"

namespace oscar::swarm::tools {

void add_snapshot(CLI::App& app, SnapshotOptions& options) {
  auto* c = app.add_subcommand(
      "snapshot", "Draw the running swarm now: world, robots, committed paths and jobs (SVG)");
  options.system.add_to(*c);
  c->add_option("-o,--output", options.output, "the SVG file")->required();
  c->add_option("--timeout", options.timeout_s, "seconds to wait for the coordinator's plan");
  options.command = c;
}

namespace {

// Where a path is at `t_ns`: between its waypoints, before the first at the first, after the
// last at the last.
Point position_at(const std::vector<SwarmWaypoint>& path, std::int64_t t_ns) {
  if (t_ns <= path.front().t_ns()) return {path.front().x(), path.front().y()};
  for (std::size_t i = 1; i < path.size(); ++i) {
    const auto& a = path[i - 1];
    const auto& b = path[i];
    if (t_ns > b.t_ns()) continue;
    const double f = b.t_ns() == a.t_ns() ? 1.0
                                          : static_cast<double>(t_ns - a.t_ns()) /
                                                static_cast<double>(b.t_ns() - a.t_ns());
    return {a.x() + f * (b.x() - a.x()), a.y() + f * (b.y() - a.y())};
  }
  return {path.back().x(), path.back().y()};
}

Polygon polygon_of(const SwarmArea& area) {
  std::vector<Point> points;
  for (std::size_t i = 0; i < area.x().size() && i < area.y().size(); ++i) {
    points.emplace_back(area.x()[i], area.y()[i]);
  }
  return make_polygon(points, "an obstacle of the coordinator's world");
}

// The newest state of each of `robots` that publishes one within `wait`.
std::map<std::string, RobotState> robot_states(DdsParticipant& participant,
                                               const std::vector<std::string>& robots,
                                               std::chrono::milliseconds wait) {
  std::mutex mutex;
  std::condition_variable arrived;
  std::map<std::string, RobotState> states;
  std::vector<std::unique_ptr<TopicReader<RobotState, RobotStatePubSubType>>> readers;
  for (const auto& robot : robots) {
    readers.push_back(std::make_unique<TopicReader<RobotState, RobotStatePubSubType>>(
        participant, topics::cue(robot + "/state"),
        qos::cue_reader(OutputOptions{.depth = 1, .reliable = false}, 1, Reliability::kBestEffort),
        [&](const RobotState& s, const auto&) {
          std::lock_guard lock(mutex);
          states[s.robot()] = s;
          arrived.notify_all();
        }));
  }
  std::unique_lock lock(mutex);  // released before the readers go
  arrived.wait_for(lock, wait, [&] { return states.size() >= robots.size(); });
  return states;
}

}  // namespace

std::string snapshot_svg(const SnapshotOptions& o) {
  auto participant = o.system.participant("oscar-swarm-snapshot");
  const auto plan = newest_from_coordinator(
      *participant, topics::swarm_plan(),
      std::chrono::milliseconds(static_cast<long>(o.timeout_s * 1000)), "swarm plan");
  // Where each robot is (robots publish at their rate; one silent for 2 s is drawn where its
  // committed path has it now).
  std::vector<std::string> robots;
  for (const auto& path : plan.paths()) robots.push_back(path.robot());
  const auto states = robot_states(*participant, robots, std::chrono::milliseconds(2000));
  const auto now = wall_now();
  WorldPicture picture;
  for (const auto& a : plan.static_obstacles()) picture.static_obstacles.push_back(polygon_of(a));
  for (const auto& m : plan.moving_obstacles()) {
    if (m.path().empty()) continue;
    WorldPicture::MovingObstacle drawn{polygon_of(m.shape()), {}, position_at(m.path(), now)};
    for (const auto& w : m.path()) drawn.path.emplace_back(w.x(), w.y());
    picture.moving_obstacles.push_back(std::move(drawn));
  }
  std::size_t jobs_to_do = 0;
  for (const auto& path : plan.paths()) {
    WorldPicture::Robot r{path.robot(), {}, {}, std::nullopt, path.radius(), false};
    if (const auto s = states.find(path.robot()); s != states.end()) {
      r.now = Point(s->second.x(), s->second.y());
      r.broken = s->second.broken();
    } else if (!path.waypoints().empty()) {
      r.now = position_at(path.waypoints(), now);
    }
    if (r.now) r.path.push_back(*r.now);
    for (const auto& w : path.waypoints()) {
      if (w.t_ns() > now) r.path.emplace_back(w.x(), w.y());
    }
    for (const auto& j : plan.jobs()) {
      const auto end = j.start_ns() + static_cast<std::int64_t>(j.duration_s() * 1e9);
      if (j.robot() != path.robot() || end <= now) continue;  // done since the plan came
      r.jobs.push_back(
          {Point(j.x(), j.y()),
           fmt::format("{} @{:+.1f}", j.id(), static_cast<double>(j.start_ns() - now) * 1e-9)});
    }
    jobs_to_do += r.jobs.size();
    picture.robots.push_back(std::move(r));
  }
  picture.caption = {
      fmt::format("oscar swarm snapshot, {} robots, {} jobs to do: static obstacles (grey), moving "
                  "obstacles now and their path (orange, dashed),",
                  plan.paths().size(), jobs_to_do),
      "robots now (discs; red: broken down) with their committed paths from now on (colour), "
      "jobs (dots: id @ start in s from now)"};
  return world_svg(picture);
}

}  // namespace oscar::swarm::tools
