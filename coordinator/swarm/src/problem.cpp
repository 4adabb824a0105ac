#include "oscar/swarm/problem.hpp"

#include <yaml-cpp/yaml.h>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "oscar/swarm/dependency_windows.hpp"

namespace oscar::swarm {

namespace {

// Locations tried per job: each costs a round of slot searches, so more than this is a typo.
constexpr long long kMaxLocationSamples = 10000;
// A transaction number in a file; the scheduler opens one per operation.
constexpr long long kMaxTransaction = 1'000'000'000;

class Parser {
 public:
  /// `live`: operations for a running swarm (oscar swarm submit): no commit, abort, set_present,
  /// remove or remove_node, and job ids may refer to jobs submitted before.
  explicit Parser(std::string source, bool live = false)
      : source_(std::move(source)), live_(live) {}

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

  // An integer within [lo, hi]: a fraction is refused, not truncated, and the range keeps the
  // conversion from double defined.
  long long integer(const YAML::Node& node, const std::string& what, long long lo,
                    long long hi) const {
    const double v = number(node, what);
    if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi)) {
      fail(node,
           fmt::format("{} = {}: expected an integer from {} to {}", what, node.Scalar(), lo, hi));
    }
    return static_cast<long long>(v);
  }

  const YAML::Node required(const YAML::Node& map, const std::string& key,
                            const std::string& what) const {
    if (!map.IsMap()) fail(map, what + ": expected a mapping");
    const YAML::Node v = map[key];
    if (!v) fail(map, fmt::format("{}: missing '{}'", what, key));
    return v;
  }

  // Fails unless `node` is a mapping with only these keys, each once: a misspelt optional key
  // would be ignored, and of two equal keys yaml-cpp reads the first.
  void check_keys(const YAML::Node& node, const std::string& what,
                  std::initializer_list<std::string_view> allowed) const {
    if (!node.IsMap()) fail(node, what + ": expected a mapping");
    std::set<std::string> seen;
    for (const auto& kv : node) {
      const std::string& key = kv.first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        fail(kv.first, fmt::format("{}: unknown key '{}' (expected one of: {})", what, key,
                                   fmt::join(allowed, ", ")));
      }
      if (!seen.insert(key).second) fail(kv.first, fmt::format("{}: '{}' given twice", what, key));
    }
  }

  // Fails unless `node` is a list: yaml-cpp would iterate a scalar as an empty list.
  YAML::Node list(const YAML::Node& node, const std::string& what) const {
    if (!node.IsSequence()) fail(node, what + ": expected a list");
    return node;
  }

  bool boolean(const YAML::Node& node, const std::string& what) const {
    bool v = false;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, v)) {
      fail(node, what + ": expected true or false");
    }
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
    check_keys(node, what, {"id", "area", "earliest_start", "latest_finish", "duration"});
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

  World world(const YAML::Node& node) const {
    check_keys(node, "world", {"static", "dynamic"});
    World w;
    if (node["static"]) {
      const auto st = list(node["static"], "world.static");
      for (std::size_t i = 0; i < st.size(); ++i) {
        w.static_obstacles.push_back(polygon(st[i], fmt::format("world.static[{}]", i)));
      }
    }
    if (node["dynamic"]) {
      const auto dyn = list(node["dynamic"], "world.dynamic");
      for (std::size_t i = 0; i < dyn.size(); ++i) {
        w.dynamic_obstacles.push_back(moving_obstacle(dyn[i], fmt::format("world.dynamic[{}]", i)));
      }
    }
    return w;
  }

  NodeSpec node(const YAML::Node& n) {
    NodeSpec s;
    s.id = text(required(n, "id", "node"), "node id");
    const std::string what = fmt::format("node '{}'", s.id);
    check_keys(n, what, {"id", "radius", "max_speed", "start", "turning_radius"});
    if (!node_ids_.insert(s.id).second) fail(n, what + ": duplicate node id");
    s.radius_m = number(required(n, "radius", what), what + " radius");
    s.max_speed_mps = number(required(n, "max_speed", what), what + " max_speed");
    if (s.radius_m < 0) fail(n["radius"], what + " radius: must be >= 0");
    if (s.max_speed_mps <= 0) fail(n["max_speed"], what + " max_speed: must be > 0");
    const auto start = required(n, "start", what);
    if (!start.IsSequence() || start.size() != 3) fail(start, what + " start: expected [x, y, t]");
    s.x = number(start[0], what + " start x");
    s.y = number(start[1], what + " start y");
    s.t = time(start[2], what + " start t");
    if (n["turning_radius"])
      s.turning_radius_m = number(n["turning_radius"], what + " turning_radius");
    if (s.turning_radius_m < 0) fail(n["turning_radius"], what + " turning_radius: must be >= 0");
    return s;
  }

  /// The operations in order; `present` is settings.present, which set_present must not undercut.
  std::vector<Operation> operations(const YAML::Node& list, double present) {
    std::vector<Operation> result;
    for (const auto& o : list) result.push_back(operation(o, present));
    return result;
  }

 private:
  MovingObstacle moving_obstacle(const YAML::Node& node, const std::string& what) const {
    check_keys(node, what, {"shape", "trajectory"});
    MovingObstacle o;
    o.shape = polygon(required(node, "shape", what), what + " shape");
    const auto traj = required(node, "trajectory", what);
    if (!traj.IsSequence() || traj.size() == 0)
      fail(traj, what + " trajectory: expected [[x, y, t], ...]");
    std::vector<Waypoint> w;
    for (const auto& q : traj) {
      if (!q.IsSequence() || q.size() != 3) fail(q, what + " trajectory: expected [x, y, t]");
      w.push_back({number(q[0], what + " x"), number(q[1], what + " y"), time(q[2], what + " t")});
      if (w.size() > 1 && w.back().t < w[w.size() - 2].t)
        fail(q, what + " trajectory: times must not decrease");
    }
    o.trajectory = Trajectory(std::move(w));
    return o;
  }

  Operation operation(const YAML::Node& o, double& present) {
    Operation op;
    op.line = o.Mark().line + 1;
    op.name = text(required(o, "op", "operation"), "operation op");
    using K = Operation::Kind;
    if (op.name == "schedule" || op.name == "reschedule") {
      op.kind = op.name == "schedule" ? K::kSchedule : K::kReschedule;
      check_keys(o, op.name, {"op", "job"});
      op.job = job_operation(o, op.name);
    } else if (op.name == "schedule_periodic") {
      op.kind = K::kPeriodic;
      check_keys(o, op.name, {"op", "ids", "area", "same_location", "start", "period", "duration"});
      op.periodic = periodic(o);
    } else if (op.name == "schedule_dependent") {
      op.kind = K::kDependent;
      check_keys(o, op.name, {"op", "jobs", "depends"});
      op.dependent = dependent(o);
    } else if (op.name == "unschedule" || op.name == "remove" || op.name == "unschedule_set") {
      op.kind = op.name == "unschedule" ? K::kUnschedule
                : op.name == "remove"   ? K::kRemove
                                        : K::kUnscheduleSet;
      check_keys(o, op.name, {"op", "id"});
      op.id = text(required(o, "id", op.name), op.name + " id");
      // A live system's jobs were scheduled by earlier submissions: the coordinator knows them.
      if (!live_ && !job_ids_.count(op.id)) {
        fail(o, fmt::format("{}: unknown job id '{}'", op.name, op.id));
      }
    } else if (live_) {
      fail(o, fmt::format("{}: not for a live swarm, where the robots commit and abort and the "
                          "present is the clock (schedule, schedule_periodic, schedule_dependent, "
                          "unschedule, unschedule_set, reschedule)",
                          op.name));
    } else if (op.name == "remove_node") {
      op.kind = K::kRemoveNode;
      check_keys(o, op.name, {"op", "node"});
      op.node = text(required(o, "node", op.name), "remove_node node");
      if (!node_ids_.count(op.node))
        fail(o["node"], fmt::format("remove_node: unknown node id '{}'", op.node));
    } else if (op.name == "commit" || op.name == "abort") {
      op.kind = op.name == "commit" ? K::kCommit : K::kAbort;
      check_keys(o, op.name, {"op", "transaction", "node"});
      finish(o, op);
    } else if (op.name == "set_present") {
      op.kind = K::kSetPresent;
      check_keys(o, op.name, {"op", "t"});
      op.t = time(required(o, "t", op.name), "set_present t");
      if (op.t < present) {
        fail(o, fmt::format("set_present: present time must not go backwards ({} < {})", op.t,
                            present));
      }
      present = op.t;
    } else {
      fail(o, fmt::format("unknown op '{}' (schedule, schedule_periodic, schedule_dependent, "
                          "unschedule, unschedule_set, remove, reschedule, remove_node, commit, "
                          "abort, set_present)",
                          op.name));
    }
    return op;
  }

  // schedule (a new job id) and reschedule (one scheduled by an earlier operation).
  JobSpec job_operation(const YAML::Node& o, const std::string& name) {
    const auto jn = required(o, "job", name);
    JobSpec j = job(jn);
    if (name == "schedule") {
      new_job_id(jn, j.id);
    } else if (!job_ids_.count(j.id)) {
      fail(jn, fmt::format("reschedule: unknown job id '{}'", j.id));
    }
    return j;
  }

  PeriodicSpec periodic(const YAML::Node& o) {
    const std::string name = "schedule_periodic";
    PeriodicSpec ps;
    const auto ids = required(o, "ids", name);
    if (!ids.IsSequence() || ids.size() == 0)
      fail(ids, "schedule_periodic ids: expected a non-empty list");
    for (const auto& id : ids) {
      ps.ids.push_back(text(id, "schedule_periodic id"));
      new_job_id(id, ps.ids.back());
    }
    ps.area = polygon(required(o, "area", name), "schedule_periodic area");
    if (o["same_location"])
      ps.same_location = boolean(o["same_location"], "schedule_periodic same_location");
    ps.start = time(required(o, "start", name), "schedule_periodic start");
    ps.period = number(required(o, "period", name), "schedule_periodic period");
    ps.duration = number(required(o, "duration", name), "schedule_periodic duration");
    if (ps.duration <= 0 || ps.period < ps.duration) {
      fail(o, "schedule_periodic: need 0 < duration <= period (seed §4.2.3)");
    }
    const double end = ps.start + static_cast<double>(ps.ids.size()) * ps.period;
    if (end > 1e6) {
      fail(o, fmt::format("schedule_periodic: the last repetition ends at start + {}·period = {}: "
                          "times must lie within ±1e6 s (precision, seed §5.3.1)",
                          ps.ids.size(), end));
    }
    return ps;
  }

  DependentSpec dependent(const YAML::Node& o) {
    DependentSpec ds;
    const auto jobs = list(required(o, "jobs", "schedule_dependent"), "schedule_dependent jobs");
    for (const auto& jn : jobs) {
      ds.jobs.push_back(job(jn));
      new_job_id(jn, ds.jobs.back().id);
    }
    if (const auto deps = o["depends"]) ds.depends = depends(deps);
    try {
      topological_order(ds.jobs, ds.depends);
    } catch (const std::invalid_argument& e) {
      fail(o["depends"] ? o["depends"] : o, e.what());
    }
    return ds;
  }

  // `C: [A, B]` per job: a scalar or a mapping in place of the list would be skipped silently.
  std::map<std::string, std::vector<std::string>> depends(const YAML::Node& node) const {
    if (!node.IsMap()) fail(node, "depends: expected a mapping of job id to a list of job ids");
    std::map<std::string, std::vector<std::string>> result;
    for (const auto& kv : node) {
      const std::string id = text(kv.first, "depends: job id");
      const std::string what = fmt::format("depends.{}", id);
      if (result.count(id)) fail(kv.first, what + ": given twice");
      if (!kv.second.IsSequence()) fail(kv.second, what + ": expected a list of job ids");
      auto& list = result[id];
      for (const auto& d : kv.second) list.push_back(text(d, what));
    }
    return result;
  }

  // commit and abort: which transaction (0 = the last open one) and optionally which node.
  void finish(const YAML::Node& o, Operation& op) const {
    if (o["transaction"]) {
      op.transaction = static_cast<TransactionId>(
          integer(o["transaction"], op.name + " transaction", 1, kMaxTransaction));
    }
    if (o["node"]) {
      op.node = text(o["node"], op.name + " node");
      if (!node_ids_.count(op.node))
        fail(o["node"], fmt::format("{}: unknown node id '{}'", op.name, op.node));
    }
  }

  void new_job_id(const YAML::Node& at, const std::string& id) {
    if (!job_ids_.insert(id).second) fail(at, fmt::format("job id '{}' is used twice", id));
  }

  std::string source_;
  bool live_ = false;
  std::set<std::string> node_ids_;
  std::set<std::string> job_ids_;
};

}  // namespace

namespace {

YAML::Node load_yaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(fmt::format("{}:{}:{}: not valid YAML/JSON: {}", source,
                                            e.mark.line + 1, e.mark.column + 1, e.msg));
  }
}

}  // namespace

World parse_world(const YAML::Node& node, const std::string& source) {
  return Parser(source).world(node);
}

JobSpec parse_job(const std::string& text, const std::string& source) {
  return Parser(source, true).job(load_yaml(text, source));
}

std::vector<Operation> parse_operations(const std::string& text, const std::string& source) {
  Parser p(source, true);
  return p.operations(p.list(load_yaml(text, source), "operations"), -1e6);  // no present to keep
}

Problem parse_problem(const std::string& text, const std::string& source) {
  Parser p(source);
  const YAML::Node root = load_yaml(text, source);
  if (!root.IsMap()) throw std::invalid_argument(source + ": expected a mapping at the top");
  p.check_keys(root, "top level", {"world", "nodes", "settings", "operations"});
  Problem problem;
  problem.source = source;
  if (const auto world = root["world"]) problem.world = p.world(world);
  for (const auto& n : p.list(p.required(root, "nodes", "problem"), "nodes")) {
    problem.nodes.push_back(p.node(n));
    problem.node_positions.push_back({n.Mark().line + 1, n.Mark().column + 1});
  }
  if (const auto st = root["settings"]) {
    p.check_keys(st, "settings",
                 {"present", "frozen_horizon", "dependency_margin", "location_samples",
                  "wait_threshold", "seed"});
    auto& s = problem.settings;
    if (st["present"]) s.present = p.time(st["present"], "settings.present");
    if (st["frozen_horizon"])
      s.frozen_horizon = p.time(st["frozen_horizon"], "settings.frozen_horizon");
    if (st["dependency_margin"])
      s.dependency_margin = p.number(st["dependency_margin"], "settings.dependency_margin");
    if (st["wait_threshold"])
      s.wait_threshold = p.number(st["wait_threshold"], "settings.wait_threshold");
    if (st["location_samples"])
      s.location_samples = static_cast<int>(
          p.integer(st["location_samples"], "settings.location_samples", 1, kMaxLocationSamples));
    if (st["seed"])
      s.seed = static_cast<unsigned>(p.integer(st["seed"], "settings.seed", 0, 4294967295));
    if (s.frozen_horizon < 0) p.fail(st["frozen_horizon"], "settings.frozen_horizon: must be >= 0");
    if (s.dependency_margin < 0)
      p.fail(st["dependency_margin"], "settings.dependency_margin: must be >= 0");
    if (s.wait_threshold < 0) p.fail(st["wait_threshold"], "settings.wait_threshold: must be >= 0");
  }
  if (const auto ops = root["operations"]) {
    problem.operations = p.operations(p.list(ops, "operations"), problem.settings.present);
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
