#include "oscar/swarm/problem_runner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <utility>

namespace oscar::swarm {

namespace {

// Adds node i of the problem; what the scheduler refuses (a start inside an obstacle, say) is
// reported at the node's place in the file.
void add_node(Scheduler& scheduler, const Problem& problem, std::size_t i) {
  try {
    scheduler.add_node(problem.nodes[i]);
  } catch (const std::invalid_argument& e) {
    if (i >= problem.node_positions.size()) throw;
    const auto& at = problem.node_positions[i];
    throw std::invalid_argument(
        fmt::format("{}:{}:{}: {}", problem.source, at.line, at.column, e.what()));
  }
}

}  // namespace

ProblemRunner::ProblemRunner(const Problem& problem)
    : problem_(problem), scheduler_(problem.world, problem.settings) {
  for (std::size_t i = 0; i < problem.nodes.size(); ++i) add_node(scheduler_, problem, i);
}

void ProblemRunner::run() {
  using K = Operation::Kind;
  for (const auto& op : problem_.operations) {
    OperationOutcome out;
    out.op = op.name;
    try {
      ScheduleResult r;
      bool result_op = true;
      switch (op.kind) {
        case K::kSchedule:
          r = scheduler_.schedule(op.job);
          break;
        case K::kPeriodic:
          r = scheduler_.schedule(op.periodic);
          break;
        case K::kDependent:
          r = scheduler_.schedule(op.dependent);
          break;
        case K::kUnschedule:
          r = scheduler_.unschedule(op.id);
          break;
        case K::kUnscheduleSet:
          r = scheduler_.unschedule_set(op.id);
          break;
        case K::kRemove:
          r = scheduler_.remove_job(op.id);
          break;
        case K::kRemoveNode:
          result_op = false;
          scheduler_.remove_node(op.node);
          out.ok = true;
          break;
        case K::kReschedule:
          r = scheduler_.reschedule(op.job);
          break;
        case K::kCommit:
        case K::kAbort: {
          result_op = false;
          const auto open = scheduler_.open_transactions();
          TransactionId id = op.transaction;
          if (id == 0) {
            if (open.empty()) throw std::invalid_argument("no open transaction");
            id = open.back();
          }
          if (op.kind == K::kCommit) {
            scheduler_.commit(id, op.node);
          } else {
            scheduler_.abort(id, op.node);
          }
          out.ok = true;
          out.transaction = id;
          break;
        }
        case K::kSetPresent:
          result_op = false;
          scheduler_.set_present(op.t);
          out.ok = true;
          break;
      }
      if (result_op) {
        out.ok = r.ok;
        out.reason = r.reason;
        out.transaction = r.transaction;
        out.jobs = r.jobs;
      }
    } catch (const std::invalid_argument& e) {
      // Only reachable when an earlier operation failed as a regular outcome (e.g. the job to
      // unschedule was never scheduled): reported, not fatal.
      out.ok = false;
      out.reason = fmt::format("{}:{}: {}", problem_.source, op.line, e.what());
    }
    outcomes_.push_back(std::move(out));
  }
}

namespace {

nlohmann::json polygon_json(const Polygon& p) {
  auto a = nlohmann::json::array();
  for (const auto& v : vertices(p)) a.push_back({v.x(), v.y()});
  return a;
}

nlohmann::json trajectory_json(const Trajectory& t) {
  auto a = nlohmann::json::array();
  for (const auto& w : t.points()) a.push_back({w.x, w.y, w.t});
  return a;
}

nlohmann::json job_json(const Job& j) {
  return {{"id", j.id}, {"node", j.node},   {"x", j.x},
          {"y", j.y},   {"start", j.start}, {"duration", j.duration}};
}

// The interval the load figures cover: from the present to the end of the last committed job of
// any node; none if that is not after the present.
std::optional<std::pair<double, double>> load_interval(const Scheduler& s) {
  double end = s.present();
  for (const auto& id : s.node_ids()) {
    for (const auto& j : s.jobs(id)) end = std::max(end, j.end());
  }
  if (end <= s.present()) return std::nullopt;
  return std::pair{s.present(), end};
}

nlohmann::json load_json(const Load& l) {
  return {{"job", l.job},
          {"motion", l.motion},
          {"stationary", l.stationary},
          {"total", l.total},
          {"velocity", l.velocity}};
}

}  // namespace

std::string ProblemRunner::to_json(int indent) const {
  nlohmann::json doc;
  doc["operations"] = nlohmann::json::array();
  for (const auto& o : outcomes_) {
    nlohmann::json j{{"op", o.op}, {"ok", o.ok}};
    if (!o.reason.empty()) j["reason"] = o.reason;
    if (o.transaction) j["transaction"] = o.transaction;
    if (!o.jobs.empty()) {
      j["jobs"] = nlohmann::json::array();
      for (const auto& job : o.jobs) j["jobs"].push_back(job_json(job));
    }
    doc["operations"].push_back(j);
  }
  doc["jobs"] = nlohmann::json::array();
  doc["nodes"] = nlohmann::json::array();
  doc["open"] = nlohmann::json::array();
  const auto interval = load_interval(scheduler_);
  if (interval) doc["load_interval"] = {interval->first, interval->second};
  for (const auto& id : scheduler_.node_ids()) {
    const auto& n = scheduler_.node(id);
    for (const auto& j : scheduler_.jobs(id)) doc["jobs"].push_back(job_json(j));
    nlohmann::json node{{"id", id},
                        {"radius", n.radius_m},
                        {"max_speed", n.max_speed_mps},
                        {"trajectory", trajectory_json(scheduler_.trajectory(id))}};
    if (interval) node["load"] = load_json(scheduler_.load(id, interval->first, interval->second));
    doc["nodes"].push_back(node);
  }
  if (!scheduler_.open_transactions().empty()) {
    // Open transactions: the working view (all open transactions applied), per node.
    for (const auto& id : scheduler_.node_ids()) {
      nlohmann::json n{{"node", id},
                       {"trajectory", trajectory_json(scheduler_.trajectory(id, false))}};
      n["jobs"] = nlohmann::json::array();
      for (const auto& j : scheduler_.jobs(id, false)) n["jobs"].push_back(job_json(j));
      doc["open"].push_back(n);
    }
    doc["open_transactions"] = scheduler_.open_transactions();
  }
  nlohmann::json world{{"static", nlohmann::json::array()}, {"dynamic", nlohmann::json::array()}};
  for (const auto& p : problem_.world.static_obstacles) world["static"].push_back(polygon_json(p));
  for (const auto& o : problem_.world.dynamic_obstacles) {
    world["dynamic"].push_back(
        {{"shape", polygon_json(o.shape)}, {"trajectory", trajectory_json(o.trajectory)}});
  }
  doc["world"] = world;
  return doc.dump(indent);
}

}  // namespace oscar::swarm
