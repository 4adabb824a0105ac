#include "oscar/swarm/problem.hpp"

#include <yaml-cpp/yaml.h>

#include <fmt/format.h>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "oscar/swarm/dependency_windows.hpp"

namespace oscar::swarm {

namespace {

class Parser {
 public:
  explicit Parser(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const {
    const auto mark = node.Mark();
    throw std::invalid_argument(
        fmt::format("{}:{}:{}: {}", source_, mark.line + 1, mark.column + 1, message));
  }

  double number(const YAML::Node& node, const std::string& what) const {
    if (!node || !node.IsScalar()) fail(node, what + ": expected a number");
    double v = 0;
    try {
      v = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, fmt::format("{}: expected a number, got '{}'", what, node.Scalar()));
    }
    if (!std::isfinite(v)) fail(node, what + ": must be finite (no NaN or inf)");
    return v;
  }

  double time(const YAML::Node& node, const std::string& what) const {
    const double t = number(node, what);
    if (std::abs(t) > 1e6) {
      fail(node,
           fmt::format("{} = {}: times must lie within ±1e6 s (precision, seed §5.3.1)", what, t));
    }
    return t;
  }

  const YAML::Node required(const YAML::Node& map, const std::string& key,
                            const std::string& what) const {
    if (!map.IsMap()) fail(map, what + ": expected a mapping");
    const YAML::Node v = map[key];
    if (!v) fail(map, fmt::format("{}: missing '{}'", what, key));
    return v;
  }

  std::string text(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar() || node.Scalar().empty())
      fail(node, what + ": expected a non-empty string");
    return node.Scalar();
  }

  Point point(const YAML::Node& node, const std::string& what) const {
    if (!node.IsSequence() || node.size() != 2) fail(node, what + ": expected [x, y]");
    return Point(number(node[0], what + " x"), number(node[1], what + " y"));
  }

  Polygon polygon(const YAML::Node& node, const std::string& what) const {
    if (!node.IsSequence()) fail(node, what + ": expected a list of [x, y]");
    std::vector<Point> pts;
    for (const auto& p : node) pts.push_back(point(p, what));
    try {
      return make_polygon(pts, what);
    } catch (const std::invalid_argument& e) {
      fail(node, e.what());
    }
  }

  JobSpec job(const YAML::Node& node) const {
    JobSpec j;
    j.id = text(required(node, "id", "job"), "job id");
    const std::string what = fmt::format("job '{}'", j.id);
    j.area = polygon(required(node, "area", what), what + " area");
    j.earliest_start = time(required(node, "earliest_start", what), what + " earliest_start");
    j.latest_finish = time(required(node, "latest_finish", what), what + " latest_finish");
    j.duration = number(required(node, "duration", what), what + " duration");
    if (j.duration <= 0) fail(node["duration"], what + " duration: must be > 0");
    if (j.latest_finish - j.earliest_start < j.duration) {
      fail(node, fmt::format("{}: window [{}, {}] is shorter than the duration {}", what,
                             j.earliest_start, j.latest_finish, j.duration));
    }
    return j;
  }

 private:
  std::string source_;
};

}  // namespace

Problem parse_problem(const std::string& text, const std::string& source) {
  Parser p(source);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(fmt::format("{}:{}:{}: not valid YAML/JSON: {}", source,
                                            e.mark.line + 1, e.mark.column + 1, e.msg));
  }
  if (!root.IsMap()) throw std::invalid_argument(source + ": expected a mapping at the top");
  Problem problem;
  problem.source = source;
  if (const auto world = root["world"]) {
    if (const auto st = world["static"]) {
      for (std::size_t i = 0; i < st.size(); ++i) {
        problem.world.static_obstacles.push_back(
            p.polygon(st[i], fmt::format("world.static[{}]", i)));
      }
    }
    if (const auto dyn = world["dynamic"]) {
      for (std::size_t i = 0; i < dyn.size(); ++i) {
        const std::string what = fmt::format("world.dynamic[{}]", i);
        MovingObstacle o;
        o.shape = p.polygon(p.required(dyn[i], "shape", what), what + " shape");
        const auto traj = p.required(dyn[i], "trajectory", what);
        if (!traj.IsSequence() || traj.size() == 0)
          p.fail(traj, what + " trajectory: expected [[x, y, t], ...]");
        std::vector<Waypoint> w;
        for (const auto& q : traj) {
          if (!q.IsSequence() || q.size() != 3) p.fail(q, what + " trajectory: expected [x, y, t]");
          w.push_back({p.number(q[0], what + " x"), p.number(q[1], what + " y"),
                       p.time(q[2], what + " t")});
          if (w.size() > 1 && w.back().t < w[w.size() - 2].t)
            p.fail(q, what + " trajectory: times must not decrease");
        }
        o.trajectory = Trajectory(std::move(w));
        problem.world.dynamic_obstacles.push_back(std::move(o));
      }
    }
  }
  const auto nodes = p.required(root, "nodes", "problem");
  std::set<std::string> node_ids;
  for (const auto& n : nodes) {
    NodeSpec s;
    s.id = p.text(p.required(n, "id", "node"), "node id");
    const std::string what = fmt::format("node '{}'", s.id);
    if (!node_ids.insert(s.id).second) p.fail(n, what + ": duplicate node id");
    s.radius_m = p.number(p.required(n, "radius", what), what + " radius");
    s.max_speed_mps = p.number(p.required(n, "max_speed", what), what + " max_speed");
    if (s.radius_m < 0) p.fail(n["radius"], what + " radius: must be >= 0");
    if (s.max_speed_mps <= 0) p.fail(n["max_speed"], what + " max_speed: must be > 0");
    const auto start = p.required(n, "start", what);
    if (!start.IsSequence() || start.size() != 3)
      p.fail(start, what + " start: expected [x, y, t]");
    s.x = p.number(start[0], what + " start x");
    s.y = p.number(start[1], what + " start y");
    s.t = p.time(start[2], what + " start t");
    if (n["turning_radius"])
      s.turning_radius_m = p.number(n["turning_radius"], what + " turning_radius");
    if (s.turning_radius_m < 0) p.fail(n["turning_radius"], what + " turning_radius: must be >= 0");
    problem.nodes.push_back(s);
  }
  if (const auto st = root["settings"]) {
    auto& s = problem.settings;
    if (st["present"]) s.present = p.time(st["present"], "settings.present");
    if (st["frozen_horizon"])
      s.frozen_horizon = p.number(st["frozen_horizon"], "settings.frozen_horizon");
    if (st["dependency_margin"])
      s.dependency_margin = p.number(st["dependency_margin"], "settings.dependency_margin");
    if (st["wait_threshold"])
      s.wait_threshold = p.number(st["wait_threshold"], "settings.wait_threshold");
    if (st["location_samples"])
      s.location_samples =
          static_cast<int>(p.number(st["location_samples"], "settings.location_samples"));
    if (s.frozen_horizon < 0) p.fail(st["frozen_horizon"], "settings.frozen_horizon: must be >= 0");
    if (s.dependency_margin < 0)
      p.fail(st["dependency_margin"], "settings.dependency_margin: must be >= 0");
    if (s.wait_threshold < 0) p.fail(st["wait_threshold"], "settings.wait_threshold: must be >= 0");
    if (s.location_samples < 1)
      p.fail(st["location_samples"], "settings.location_samples: must be >= 1");
  }
  std::set<std::string> known_jobs;
  double present = problem.settings.present;
  if (const auto ops = root["operations"]) {
    for (const auto& o : ops) {
      Operation op;
      op.line = o.Mark().line + 1;
      op.name = p.text(p.required(o, "op", "operation"), "operation op");
      using K = Operation::Kind;
      auto add_job_id = [&](const YAML::Node& at, const std::string& id) {
        if (!known_jobs.insert(id).second) p.fail(at, fmt::format("job id '{}' is used twice", id));
      };
      if (op.name == "schedule" || op.name == "reschedule") {
        op.kind = op.name == "schedule" ? K::kSchedule : K::kReschedule;
        const auto jn = p.required(o, "job", op.name);
        op.job = p.job(jn);
        if (op.kind == K::kSchedule) {
          add_job_id(jn, op.job.id);
        } else if (!known_jobs.count(op.job.id)) {
          p.fail(jn, fmt::format("reschedule: unknown job id '{}'", op.job.id));
        }
      } else if (op.name == "schedule_periodic") {
        op.kind = K::kPeriodic;
        auto& ps = op.periodic;
        const auto ids = p.required(o, "ids", op.name);
        if (!ids.IsSequence() || ids.size() == 0)
          p.fail(ids, "schedule_periodic ids: expected a non-empty list");
        for (const auto& id : ids) {
          ps.ids.push_back(p.text(id, "schedule_periodic id"));
          add_job_id(id, ps.ids.back());
        }
        ps.area = p.polygon(p.required(o, "area", op.name), "schedule_periodic area");
        if (o["same_location"]) ps.same_location = o["same_location"].as<bool>();
        ps.start = p.time(p.required(o, "start", op.name), "schedule_periodic start");
        ps.period = p.number(p.required(o, "period", op.name), "schedule_periodic period");
        ps.duration = p.number(p.required(o, "duration", op.name), "schedule_periodic duration");
        if (ps.duration <= 0 || ps.period < ps.duration) {
          p.fail(o, "schedule_periodic: need 0 < duration <= period (seed §4.2.3)");
        }
      } else if (op.name == "schedule_dependent") {
        op.kind = K::kDependent;
        const auto jobs = p.required(o, "jobs", op.name);
        for (const auto& jn : jobs) {
          op.dependent.jobs.push_back(p.job(jn));
          add_job_id(jn, op.dependent.jobs.back().id);
        }
        if (const auto deps = o["depends"]) {
          for (const auto& kv : deps) {
            auto& list = op.dependent.depends[kv.first.as<std::string>()];
            for (const auto& d : kv.second) list.push_back(p.text(d, "depends"));
          }
        }
        try {
          topological_order(op.dependent.jobs, op.dependent.depends);
        } catch (const std::invalid_argument& e) {
          p.fail(o["depends"] ? o["depends"] : o, e.what());
        }
      } else if (op.name == "unschedule" || op.name == "remove") {
        op.kind = op.name == "unschedule" ? K::kUnschedule : K::kRemove;
        op.id = p.text(p.required(o, "id", op.name), op.name + " id");
        if (!known_jobs.count(op.id))
          p.fail(o, fmt::format("{}: unknown job id '{}'", op.name, op.id));
      } else if (op.name == "commit" || op.name == "abort") {
        op.kind = op.name == "commit" ? K::kCommit : K::kAbort;
        if (o["transaction"]) {
          const double t = p.number(o["transaction"], op.name + " transaction");
          if (t < 1 || t != std::floor(t))
            p.fail(o["transaction"], op.name + " transaction: expected a positive integer");
          op.transaction = static_cast<TransactionId>(t);
        }
        if (o["node"]) {
          op.node = p.text(o["node"], op.name + " node");
          if (!node_ids.count(op.node))
            p.fail(o["node"], fmt::format("{}: unknown node id '{}'", op.name, op.node));
        }
      } else if (op.name == "set_present") {
        op.kind = K::kSetPresent;
        op.t = p.time(p.required(o, "t", op.name), "set_present t");
        if (op.t < present) {
          p.fail(o, fmt::format("set_present: present time must not go backwards ({} < {})", op.t,
                                present));
        }
        present = op.t;
      } else {
        p.fail(o, fmt::format("unknown op '{}' (schedule, schedule_periodic, schedule_dependent, "
                              "unschedule, remove, reschedule, commit, abort, set_present)",
                              op.name));
      }
      problem.operations.push_back(std::move(op));
    }
  }
  return problem;
}

Problem load_problem(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot read the file", path));
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_problem(buffer.str(), path);
}

}  // namespace oscar::swarm
