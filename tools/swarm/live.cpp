// oscar swarm submit FILE|--job YAML and oscar swarm status [--json] (docs/swarm.md).
#include "live.hpp"

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "oscar/input.hpp"
#include "oscar/output.hpp"
#include "oscar/swarm/problem.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "svg.hpp"

namespace oscar::swarm::tools {

void add_submit(CLI::App& app, SubmitOptions& options) {
  auto* c = app.add_subcommand(
      "submit", "Submit jobs to the running system's coordinator and wait until robots took them");
  options.system.add_to(*c);
  c->add_option("file", options.file,
                "operations as in a problem file's `operations:` (schedule, schedule_periodic, "
                "schedule_dependent, unschedule, unschedule_set, reschedule); times in seconds "
                "from now");
  c->add_option("--job", options.jobs,
                "a job to schedule, as YAML: '{id: J1, area: [[0,0],[1,0],[1,1]], "
                "earliest_start: 5, latest_finish: 60, duration: 3}' (repeatable)");
  c->add_option("--timeout", options.timeout_s, "seconds to wait for each request's outcome");
  c->add_flag("--json", options.json, "print every reply as JSON, one per line");
  options.command = c;
}

void add_status(CLI::App& app, StatusOptions& options) {
  auto* c = app.add_subcommand("status", "The running swarm: robots, jobs, open transactions");
  options.system.add_to(*c);
  c->add_option("--timeout", options.timeout_s, "seconds to wait for the coordinator's status");
  c->add_flag("--json", options.json, "print JSON");
  options.command = c;
}

void add_snapshot(CLI::App& app, SnapshotOptions& options) {
  auto* c = app.add_subcommand(
      "snapshot", "Draw the running swarm now: world, robots, committed paths and jobs (SVG)");
  options.system.add_to(*c);
  c->add_option("-o,--output", options.output, "the SVG file")->required();
  c->add_option("--timeout", options.timeout_s, "seconds to wait for the coordinator's plan");
  options.command = c;
}

namespace {

SwarmJobSpec wire_job(const JobSpec& j, std::int64_t now) {
  SwarmJobSpec w;
  w.id(j.id);
  for (const auto& p : vertices(j.area)) {
    w.area().x().push_back(p.x());
    w.area().y().push_back(p.y());
  }
  w.earliest_start_ns(now + static_cast<std::int64_t>(j.earliest_start * 1e9));
  w.latest_finish_ns(now + static_cast<std::int64_t>(j.latest_finish * 1e9));
  w.duration_s(j.duration);
  return w;
}

// One request per operation; times count from `now`.
SwarmRequest request_of(const Operation& op, const std::string& source, std::int64_t now) {
  SwarmRequest r;
  switch (op.kind) {
    case Operation::Kind::kSchedule:
      r.kind(SWARM_SCHEDULE);
      r.jobs().push_back(wire_job(op.job, now));
      break;
    case Operation::Kind::kReschedule:
      r.kind(SWARM_RESCHEDULE);
      r.jobs().push_back(wire_job(op.job, now));
      break;
    case Operation::Kind::kUnschedule:
      r.kind(SWARM_UNSCHEDULE);
      r.job_id(op.id);
      break;
    case Operation::Kind::kUnscheduleSet:
      r.kind(SWARM_UNSCHEDULE_SET);
      r.job_id(op.id);
      break;
    case Operation::Kind::kPeriodic: {
      const auto& p = op.periodic;
      r.kind(SWARM_PERIODIC);
      r.periodic_ids(p.ids);
      r.jobs().push_back(
          wire_job({p.ids.front(), p.area, p.start, p.start + p.period, p.duration}, now));
      r.period_s(p.period);
      r.same_location(p.same_location);
      break;
    }
    case Operation::Kind::kDependent:
      r.kind(SWARM_DEPENDENT);
      for (const auto& j : op.dependent.jobs) r.jobs().push_back(wire_job(j, now));
      for (const auto& [job, after] : op.dependent.depends) {
        SwarmDependency d;
        d.job(job);
        d.after(after);
        r.depends().push_back(d);
      }
      break;
    default:
      throw std::invalid_argument(fmt::format(
          "{}:{}: {}: not for a live swarm (there the robots commit and abort, and the present "
          "is the clock); submit schedules, unschedules and reschedules",
          source, op.line, op.name));
  }
  return r;
}

const char* outcome_name(SwarmOutcome o) {
  switch (o) {
    case SWARM_PLANNED:
      return "planned";
    case SWARM_COMMITTED:
      return "committed";
    case SWARM_REFUSED:
      return "refused";
    case SWARM_ABORTED:
      return "aborted";
  }
  return "?";
}

// A placed job as JSON; its start in seconds from `now`.
nlohmann::json job_json(const SwarmPlacedJob& j, std::int64_t now) {
  return {{"id", j.id()},
          {"robot", j.robot()},
          {"x", j.x()},
          {"y", j.y()},
          {"start_s", static_cast<double>(j.start_ns() - now) * 1e-9},
          {"duration_s", j.duration_s()}};
}

nlohmann::json reply_json(const SwarmReply& r, std::int64_t now) {
  auto jobs = nlohmann::json::array();
  for (const auto& j : r.jobs()) jobs.push_back(job_json(j, now));
  return {{"request", r.request()},
          {"outcome", outcome_name(r.outcome())},
          {"transaction", r.transaction()},
          {"reason", r.reason()},
          {"jobs", jobs}};
}

std::vector<SwarmRequest> requests_of(const SubmitOptions& o, std::int64_t now) {
  std::vector<SwarmRequest> result;
  if (!o.file.empty()) {
    std::ifstream in(o.file);
    if (!in) throw std::invalid_argument("cannot read '" + o.file + "'");
    std::stringstream text;
    text << in.rdbuf();
    for (const auto& op : parse_operations(text.str(), o.file)) {
      result.push_back(request_of(op, o.file, now));
    }
  }
  for (std::size_t i = 0; i < o.jobs.size(); ++i) {
    Operation op;
    op.job = parse_job(o.jobs[i], fmt::format("--job {}", i + 1));
    result.push_back(request_of(op, "--job", now));
  }
  if (result.empty()) throw std::invalid_argument("nothing to submit: give a FILE or --job");
  return result;
}

}  // namespace

int run_submit(const SubmitOptions& o) {
  const auto now = wall_now();
  const auto requests = requests_of(o, now);
  auto participant = o.system.participant("oscar-swarm-submit");
  const std::string sender = fmt::format("oscar-swarm-submit-{}", getpid());
  std::mutex mutex;
  std::condition_variable changed;
  std::map<unsigned long long, SwarmReply> final_replies;
  TopicReader<SwarmReply, SwarmReplyPubSubType> replies(
      *participant, topics::swarm_reply(), [&](const SwarmReply& r, const auto&) {
        if (r.sender() != sender) return;
        std::lock_guard lock(mutex);
        if (o.json) fmt::print("{}\n", reply_json(r, now).dump());
        if (r.outcome() != SWARM_PLANNED) final_replies[r.request()] = r;
        changed.notify_all();
      });
  TopicWriter<SwarmRequest, SwarmRequestPubSubType> writer(*participant, topics::swarm_request());
  const auto wait = std::chrono::milliseconds(static_cast<long>(o.timeout_s * 1000));
  const auto until_matched = std::chrono::steady_clock::now() + wait;
  while (writer.matched() == 0 || replies.matched() == 0) {
    if (std::chrono::steady_clock::now() > until_matched) {
      std::fprintf(stderr,
                   "oscar swarm submit: no coordinator with a swarm reads oscar/swarm/request on "
                   "domain %d (does the system file have coordinator: swarm:?)\n",
                   participant->domain());
      return 2;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  unsigned long long id = 0;
  for (auto r : requests) {
    r.sender(sender);
    r.id(++id);
    writer.write(r);
  }
  std::unique_lock lock(mutex);
  const bool all = changed.wait_for(lock, wait * static_cast<long>(requests.size()),
                                    [&] { return final_replies.size() == requests.size(); });
  int code = all ? 0 : 2;
  for (unsigned long long i = 1; i <= id; ++i) {
    const auto it = final_replies.find(i);
    if (it == final_replies.end()) {
      fmt::print(stderr, "request {}: no outcome within {:.1f} s\n", i, o.timeout_s);
      continue;
    }
    const auto& r = it->second;
    if (r.outcome() != SWARM_COMMITTED) code = std::max(code, 1);
    if (o.json) continue;
    if (r.outcome() != SWARM_COMMITTED) {
      fmt::print("request {}: {}: {}\n", i, outcome_name(r.outcome()), r.reason());
      continue;
    }
    for (const auto& j : r.jobs()) {
      fmt::print(
          "{}: committed on {} at ({:.2f}, {:.2f}), start in {:.1f} s for {:.1f} s "
          "(transaction {})\n",
          j.id(), j.robot(), j.x(), j.y(), static_cast<double>(j.start_ns() - now) * 1e-9,
          j.duration_s(), r.transaction());
    }
    if (r.jobs().empty())
      fmt::print("request {}: committed (transaction {})\n", i, r.transaction());
  }
  return code;
}

int run_status(const StatusOptions& o) {
  auto participant = o.system.participant("oscar-swarm-status");
  std::mutex mutex;
  std::condition_variable arrived;
  std::optional<SwarmStatus> status;
  TopicReader<SwarmStatus, SwarmStatusPubSubType> reader(*participant, topics::swarm_status(),
                                                         [&](const SwarmStatus& s, const auto&) {
                                                           std::lock_guard lock(mutex);
                                                           status = s;
                                                           arrived.notify_all();
                                                         });
  std::unique_lock lock(mutex);
  if (!arrived.wait_for(lock, std::chrono::milliseconds(static_cast<long>(o.timeout_s * 1000)),
                        [&] { return status.has_value(); })) {
    std::fprintf(stderr,
                 "oscar swarm status: no coordinator published a swarm status on domain %d "
                 "within %.1f s (does the system file have coordinator: swarm:?)\n",
                 participant->domain(), o.timeout_s);
    return 2;
  }
  const auto& s = *status;
  if (o.json) {
    auto jobs = nlohmann::json::array();
    for (const auto& j : s.jobs()) jobs.push_back(job_json(j, s.now_ns()));
    const nlohmann::json doc{{"robots", s.robots()},
                             {"lost_robots", s.lost_robots()},
                             {"jobs", jobs},
                             {"open_transactions", s.open_transactions()},
                             {"jobs_submitted", s.jobs_submitted()},
                             {"jobs_committed", s.jobs_committed()},
                             {"naks", s.naks()},
                             {"timeouts", s.timeouts()},
                             {"replans", s.replans()}};
    fmt::print("{}\n", doc.dump(2));
    return 0;
  }
  fmt::print("robots: {} in planning", s.robots().size());
  if (!s.lost_robots().empty()) fmt::print(", lost: {}", fmt::join(s.lost_robots(), ", "));
  fmt::print("\njobs: {} submitted, {} committed, {} to do; open transactions: {}\n",
             s.jobs_submitted(), s.jobs_committed(), s.jobs().size(), s.open_transactions().size());
  fmt::print("naks: {}, timeouts: {}, re-plans: {}\n", s.naks(), s.timeouts(), s.replans());
  for (const auto& j : s.jobs()) {
    fmt::print("  {:<12} {:<10} ({:7.2f}, {:7.2f})  start {:+8.1f} s  {:6.1f} s\n", j.id(),
               j.robot(), j.x(), j.y(), static_cast<double>(j.start_ns() - s.now_ns()) * 1e-9,
               j.duration_s());
  }
  return 0;
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

// The coordinator's newest plan (published transient local: it comes at once if there is one).
std::optional<SwarmPlan> latest_plan(DdsParticipant& participant, std::chrono::milliseconds wait) {
  std::mutex mutex;
  std::condition_variable arrived;
  std::optional<SwarmPlan> plan;
  TopicReader<SwarmPlan, SwarmPlanPubSubType> reader(participant, topics::swarm_plan(),
                                                     [&](const SwarmPlan& p, const auto&) {
                                                       std::lock_guard lock(mutex);
                                                       plan = p;
                                                       arrived.notify_all();
                                                     });
  std::unique_lock lock(mutex);  // released before the reader goes (its callback takes it)
  arrived.wait_for(lock, wait, [&] { return plan.has_value(); });
  return plan;
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
  const auto plan =
      latest_plan(*participant, std::chrono::milliseconds(static_cast<long>(o.timeout_s * 1000)));
  if (!plan) {
    throw std::runtime_error(fmt::format(
        "no coordinator published a swarm plan on domain {} within {:.1f} s (does the system "
        "file have coordinator: swarm:?)",
        participant->domain(), o.timeout_s));
  }
  // Where each robot is (robots publish at their rate; one silent for 2 s is drawn where its
  // committed path has it now).
  std::vector<std::string> robots;
  for (const auto& path : plan->paths()) robots.push_back(path.robot());
  const auto states = robot_states(*participant, robots, std::chrono::milliseconds(2000));
  const auto now = wall_now();
  WorldPicture picture;
  picture.caption = {
      fmt::format("oscar swarm snapshot, {} robots, {} jobs to do: static obstacles (grey), moving "
                  "obstacles now and their path (orange, dashed),",
                  plan->paths().size(), plan->jobs().size()),
      "robots now (discs; red: broken down) with their committed paths from now on (colour), "
      "jobs (dots: id @ start in s from now)"};
  for (const auto& a : plan->static_obstacles()) picture.static_obstacles.push_back(polygon_of(a));
  for (const auto& m : plan->moving_obstacles()) {
    if (m.path().empty()) continue;
    WorldPicture::MovingObstacle drawn{polygon_of(m.shape()), {}, position_at(m.path(), now)};
    for (const auto& w : m.path()) drawn.path.emplace_back(w.x(), w.y());
    picture.moving_obstacles.push_back(std::move(drawn));
  }
  for (const auto& path : plan->paths()) {
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
    for (const auto& j : plan->jobs()) {
      const auto end = j.start_ns() + static_cast<std::int64_t>(j.duration_s() * 1e9);
      if (j.robot() != path.robot() || end <= now) continue;  // done since the plan came
      r.jobs.push_back(
          {Point(j.x(), j.y()),
           fmt::format("{} @{:+.1f}", j.id(), static_cast<double>(j.start_ns() - now) * 1e-9)});
    }
    picture.robots.push_back(std::move(r));
  }
  return world_svg(picture);
}

}  // namespace oscar::swarm::tools
