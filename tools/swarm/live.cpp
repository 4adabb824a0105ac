// oscar swarm submit FILE|--job YAML and oscar swarm status [--json] (docs/swarm.md); oscar swarm
// snapshot is in snapshot.cpp.
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

#include "coordinator_topic.hpp"
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
  return send_requests(o.system, "submit", requests_of(o, now), o.timeout_s, o.json, now);
}

int send_requests(const SystemOptions& system, const std::string& command,
                  const std::vector<SwarmRequest>& requests, double timeout_s, bool json,
                  std::int64_t now) {
  auto participant = system.participant("oscar-swarm-" + command, ToolAuthority::kActAsBoot);
  const std::string sender = fmt::format("oscar-swarm-{}-{}", command, getpid());
  std::mutex mutex;
  std::condition_variable changed;
  std::map<unsigned long long, SwarmReply> final_replies;
  TopicReader<SwarmReply, SwarmReplyPubSubType> replies(
      *participant, topics::swarm_reply(), [&](const SwarmReply& r, const auto&) {
        if (r.sender() != sender) return;
        std::lock_guard lock(mutex);
        if (json) fmt::print("{}\n", reply_json(r, now).dump());
        if (r.outcome() != SWARM_PLANNED) final_replies[r.request()] = r;
        changed.notify_all();
      });
  TopicWriter<SwarmRequest, SwarmRequestPubSubType> writer(*participant, topics::swarm_request());
  const auto wait = std::chrono::milliseconds(static_cast<long>(timeout_s * 1000));
  const auto until_matched = std::chrono::steady_clock::now() + wait;
  while (writer.matched() == 0 || replies.matched() == 0) {
    if (std::chrono::steady_clock::now() > until_matched) {
      fmt::print(stderr,
                 "oscar swarm {}: no coordinator with a swarm reads oscar/swarm/request on "
                 "domain {} (does the system file have coordinator: swarm:?)\n",
                 command, participant->domain());
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
      fmt::print(stderr, "request {}: no outcome within {:.1f} s\n", i, timeout_s);
      continue;
    }
    const auto& r = it->second;
    if (r.outcome() != SWARM_COMMITTED) code = std::max(code, 1);
    if (json) continue;
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
  std::optional<SwarmStatus> status;
  try {
    status = newest_from_coordinator(
        *participant, topics::swarm_status(),
        std::chrono::milliseconds(static_cast<long>(o.timeout_s * 1000)), "swarm status");
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "oscar swarm status: %s\n", e.what());
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
                             {"replans", s.replans()},
                             {"obstacles", s.obstacles()}};
    fmt::print("{}\n", doc.dump(2));
    return 0;
  }
  fmt::print("robots: {} in planning", s.robots().size());
  if (!s.lost_robots().empty()) fmt::print(", lost: {}", fmt::join(s.lost_robots(), ", "));
  fmt::print("\njobs: {} submitted, {} committed, {} to do; open transactions: {}\n",
             s.jobs_submitted(), s.jobs_committed(), s.jobs().size(), s.open_transactions().size());
  fmt::print("naks: {}, timeouts: {}, re-plans: {}\n", s.naks(), s.timeouts(), s.replans());
  fmt::print("obstacles: {}\n",
             s.obstacles().empty() ? "none" : fmt::format("{}", fmt::join(s.obstacles(), ", ")));
  for (const auto& j : s.jobs()) {
    fmt::print("  {:<12} {:<10} ({:7.2f}, {:7.2f})  start {:+8.1f} s  {:6.1f} s\n", j.id(),
               j.robot(), j.x(), j.y(), static_cast<double>(j.start_ns() - s.now_ns()) * 1e-9,
               j.duration_s());
  }
  return 0;
}

}  // namespace oscar::swarm::tools
