#include "oscar/swarm_yaml.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

namespace oscar {
namespace {

std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string waypoint_yaml(const SwarmWaypoint& w) {
  return fmt::format("{{x: {}, y: {}, t_ns: {}}}", w.x(), w.y(), w.t_ns());
}

std::string section_yaml(const TrajectorySection& s) {
  std::string points;
  for (const auto& w : s.waypoints()) points += (points.empty() ? "" : ", ") + waypoint_yaml(w);
  return fmt::format("{{from_ns: {}, to_ns: {}, open_end: {}, waypoints: [{}]}}", s.from_ns(),
                     s.to_ns(), s.open_end(), points);
}

std::string job_yaml(const RobotJob& j) {
  return fmt::format(
      "{{id: {}, x: {}, y: {}, start_ns: {}, end_ns: {}, earliest_start_ns: {}, "
      "latest_finish_ns: {}}}",
      quoted(j.id()), j.x(), j.y(), j.start_ns(), j.end_ns(), j.earliest_start_ns(),
      j.latest_finish_ns());
}

template <class T, class F>
std::string list_yaml(const std::vector<T>& items, F item_yaml) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ", ") + item_yaml(i);
  return "[" + out + "]";
}

// Reading: each member of a map by name, the map's other keys refused.
using Members = std::map<std::string, std::function<void(const YAML::Node&, const std::string&)>>;

void read_map(const YAML::Node& node, const std::string& where, const Members& members) {
  if (!node.IsMap()) {
    throw std::invalid_argument((where.empty() ? "trajectory" : where) + ": expected a map");
  }
  for (const auto& kv : node) {
    const auto key = kv.first.as<std::string>();
    const auto m = members.find(key);
    const std::string path = where.empty() ? key : where + "." + key;
    if (m == members.end()) throw std::invalid_argument(path + ": no such member");
    m->second(kv.second, path);
  }
}

template <class T>
T scalar(const YAML::Node& node, const std::string& where, const char* what) {
  if (!node.IsScalar()) throw std::invalid_argument(fmt::format("{}: expected {}", where, what));
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw std::invalid_argument(fmt::format("{}: '{}' is no {}", where, node.Scalar(), what));
  }
}

template <class T, class F>
std::vector<T> read_list(const YAML::Node& node, const std::string& where, F read_item) {
  if (!node.IsSequence()) throw std::invalid_argument(where + ": expected a list");
  std::vector<T> out;
  for (std::size_t i = 0; i < node.size(); ++i) {
    out.push_back(read_item(node[i], fmt::format("{}[{}]", where, i)));
  }
  return out;
}

SwarmWaypoint read_waypoint(const YAML::Node& node, const std::string& where) {
  SwarmWaypoint w;
  read_map(node, where,
           {{"x", [&](auto& n, auto& p) { w.x(scalar<double>(n, p, "number")); }},
            {"y", [&](auto& n, auto& p) { w.y(scalar<double>(n, p, "number")); }},
            {"t_ns", [&](auto& n, auto& p) { w.t_ns(scalar<std::int64_t>(n, p, "integer")); }}});
  return w;
}

TrajectorySection read_section(const YAML::Node& node, const std::string& where) {
  TrajectorySection s;
  read_map(
      node, where,
      {{"from_ns", [&](auto& n, auto& p) { s.from_ns(scalar<std::int64_t>(n, p, "integer")); }},
       {"to_ns", [&](auto& n, auto& p) { s.to_ns(scalar<std::int64_t>(n, p, "integer")); }},
       {"open_end", [&](auto& n, auto& p) { s.open_end(scalar<bool>(n, p, "boolean")); }},
       {"waypoints",
        [&](auto& n, auto& p) { s.waypoints(read_list<SwarmWaypoint>(n, p, read_waypoint)); }}});
  return s;
}

RobotJob read_job(const YAML::Node& node, const std::string& where) {
  RobotJob j;
  auto ns = [](auto set) {
    return [set](const YAML::Node& n, const std::string& p) {
      set(scalar<std::int64_t>(n, p, "integer"));
    };
  };
  read_map(node, where,
           {{"id", [&](auto& n, auto& p) { j.id(scalar<std::string>(n, p, "string")); }},
            {"x", [&](auto& n, auto& p) { j.x(scalar<double>(n, p, "number")); }},
            {"y", [&](auto& n, auto& p) { j.y(scalar<double>(n, p, "number")); }},
            {"start_ns", ns([&](std::int64_t v) { j.start_ns(v); })},
            {"end_ns", ns([&](std::int64_t v) { j.end_ns(v); })},
            {"earliest_start_ns", ns([&](std::int64_t v) { j.earliest_start_ns(v); })},
            {"latest_finish_ns", ns([&](std::int64_t v) { j.latest_finish_ns(v); })}});
  return j;
}

}  // namespace

std::string to_yaml(const Trajectory& t) {
  return fmt::format(
      "{{robot: {}, transaction: {}, sections: {}, jobs_added: {}, jobs_removed: {}}}",
      quoted(t.robot()), t.transaction(), list_yaml(t.sections(), section_yaml),
      list_yaml(t.jobs_added(), job_yaml), list_yaml(t.jobs_removed(), quoted));
}

Trajectory trajectory_from_yaml(const std::string& text) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(fmt::format("trajectory: no YAML: {}", e.what()));
  }
  Trajectory t;
  read_map(
      root, "",
      {{"robot", [&](auto& n, auto& p) { t.robot(scalar<std::string>(n, p, "string")); }},
       {"transaction",
        [&](auto& n, auto& p) { t.transaction(scalar<std::uint64_t>(n, p, "integer")); }},
       {"sections",
        [&](auto& n, auto& p) { t.sections(read_list<TrajectorySection>(n, p, read_section)); }},
       {"jobs_added", [&](auto& n, auto& p) { t.jobs_added(read_list<RobotJob>(n, p, read_job)); }},
       {"jobs_removed", [&](auto& n, auto& p) {
          t.jobs_removed(
              read_list<std::string>(n, p, [](const YAML::Node& i, const std::string& w) {
                return scalar<std::string>(i, w, "string");
              }));
        }}});
  return t;
}

}  // namespace oscar
