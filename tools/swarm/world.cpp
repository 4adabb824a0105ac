// oscar swarm world add NAME --polygon P | --shape S (--path P | --loop L), oscar swarm world
// remove NAME... (docs/swarm.md, "A world that changes").
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "live.hpp"
#include "oscar/time.hpp"

namespace oscar::swarm::tools {

void add_world(CLI::App& app, WorldOptions& options) {
  auto* c = app.add_subcommand(
      "world", "Change the running swarm's world: add or remove obstacles (robots re-planned)");
  c->require_subcommand(1);
  options.system.add_to(*c);
  c->add_option("--timeout", options.timeout_s, "seconds to wait for the outcome");
  c->add_flag("--json", options.json, "print every reply as JSON, one per line");
  auto* add = c->add_subcommand("add", "add an obstacle; it counts from the frozen horizon on");
  add->add_option("name", options.name, "the obstacle's name (to remove it by)")->required();
  auto* polygon = add->add_option("--polygon", options.polygon,
                                  "a standing obstacle: '[[x, y], ...]' (m, world frame)");
  auto* shape = add->add_option("--shape", options.shape,
                                "a moving obstacle's shape around its origin: '[[x, y], ...]'");
  auto* path = add->add_option("--path", options.path,
                               "with --shape: where its origin is when, '[[x, y, t], ...]' with t "
                               "in seconds from now; it exists only meanwhile");
  auto* loop = add->add_option("--loop", options.loop,
                               "with --shape: a loop '[[x, y, t], ...]' from t = 0 to its period, "
                               "ending where it starts, restarting at every multiple of the "
                               "period since the Unix epoch");
  polygon->excludes(shape);
  path->needs(shape)->excludes(loop);
  loop->needs(shape);
  auto* remove = c->add_subcommand("remove", "remove obstacles by name");
  remove->add_option("names", options.names, "the obstacles' names")->required();
  add->fallthrough();  // -d, --timeout, ... after the subcommand belong to `world`
  remove->fallthrough();
  options.add = add;
  options.remove = remove;
  options.command = c;
}

namespace {

// A YAML list of points of `count` finite numbers.
std::vector<std::vector<double>> points(const std::string& text, std::size_t count,
                                        const std::string& option) {
  const std::string form = count == 2 ? "[[x, y], ...]" : "[[x, y, t], ...]";
  YAML::Node node;
  try {
    node = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(fmt::format("{}: not YAML: {}", option, e.what()));
  }
  if (!node.IsSequence()) throw std::invalid_argument(fmt::format("{}: expected {}", option, form));
  std::vector<std::vector<double>> result;
  for (const auto& p : node) {
    std::vector<double> v;
    if (p.IsSequence() && p.size() == count) {
      for (const auto& x : p) {
        try {
          v.push_back(x.as<double>());
        } catch (const YAML::Exception&) {
        }
      }
    }
    if (v.size() != count ||
        !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); })) {
      throw std::invalid_argument(fmt::format("{}: point {} is not [{}] of finite numbers", option,
                                              result.size() + 1, count == 2 ? "x, y" : "x, y, t"));
    }
    result.push_back(std::move(v));
  }
  return result;
}

SwarmObstacle obstacle_of(const WorldOptions& o, std::int64_t now) {
  if (o.polygon.empty() && o.shape.empty()) {
    throw std::invalid_argument("world add: give --polygon, or --shape with --path or --loop");
  }
  if (!o.shape.empty() && o.path.empty() && o.loop.empty()) {
    throw std::invalid_argument("world add: --shape moves along --path or --loop");
  }
  SwarmObstacle obstacle;
  obstacle.name(o.name);
  const bool moving = !o.shape.empty();
  for (const auto& p : points(moving ? o.shape : o.polygon, 2, moving ? "--shape" : "--polygon")) {
    obstacle.shape().x().push_back(p[0]);
    obstacle.shape().y().push_back(p[1]);
  }
  if (!moving) return obstacle;
  const bool loop = !o.loop.empty();
  for (const auto& p : points(loop ? o.loop : o.path, 3, loop ? "--loop" : "--path")) {
    SwarmWaypoint w;
    w.x(p[0]);
    w.y(p[1]);
    w.t_ns((loop ? 0 : now) + std::llround(p[2] * 1e9));
    obstacle.path().push_back(w);
  }
  if (loop && !obstacle.path().empty()) obstacle.loop_ns(obstacle.path().back().t_ns());
  return obstacle;
}

}  // namespace

int run_world(const WorldOptions& o) {
  const auto now = wall_now();
  SwarmRequest r;
  if (o.add->parsed()) {
    r.kind(SWARM_ADD_OBSTACLES);
    r.obstacles().push_back(obstacle_of(o, now));
  } else {
    r.kind(SWARM_REMOVE_OBSTACLES);
    r.obstacle_names(o.names);
  }
  return send_requests(o.system, "world", {r}, o.timeout_s, o.json, now);
}

}  // namespace oscar::swarm::tools
