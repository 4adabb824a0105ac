// oscar bench swarm --live: robots, coordinator and safety monitor booted on this host; figures,
// no verdict.
#include "live_bench.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "oscar/swarm_types.hpp"
#include "oscar/testing/booted_system.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::bench {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr double kSpacing = 4;  // m between robots' starts
constexpr int kPerModule = 10;  // robots per module process

std::string robot_name(int i) { return fmt::format("r{}", i); }

// Robots on a grid of kSpacing, ten per module; the monitor; the coordinator's swarm.
std::string system_yaml(int robots, int columns) {
  std::ostringstream y;
  y << "system: bench_swarm_live\nmodules:\n";
  for (int first = 0; first < robots; first += kPerModule) {
    y << fmt::format("  - name: fleet{}\n    mode: {{ continuous: 100ms }}\n    kernels:\n",
                     first / kPerModule);
    for (int i = first; i < std::min(robots, first + kPerModule); ++i) {
      const double x = kSpacing * (i % columns), yy = kSpacing * (i / columns);
      y << fmt::format(
          "      - {{ type: robot_sim, name: {}, params: {{ start_x: {}, start_y: {}, radius: 0.3, "
          "max_speed: 1.5 }}{} }}\n",
          robot_name(i), x, yy, i == first ? "" : ", mode: { single_step: { trigger: module } }");
    }
  }
  y << "  - name: monitor\n    mode: { continuous: 50ms }\n    kernels:\n"
       "      - type: safety_monitor\n        name: safety\n        inputs: { ";
  for (int i = 0; i < robots; ++i) {
    y << (i ? ", " : "") << robot_name(i) << ": " << robot_name(i) << "/state";
  }
  y << " }\ncoordinator:\n  swarm: { frozen_horizon_ms: 1000, ack_timeout_ms: 400 }\n";
  return y.str();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

// CPU seconds (user + system) of the process whose command line holds `a` and `b`, or -1.
double cpu_seconds(const std::string& a, const std::string& b) {
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    std::ifstream cmd(e.path() / "cmdline");
    std::string line;
    std::getline(cmd, line, '\0');
    std::string all = line, part;
    while (std::getline(cmd, part, '\0')) all += " " + part;
    if (all.find(a) == std::string::npos || all.find(b) == std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string text((std::istreambuf_iterator<char>(stat)), {});
    std::istringstream rest(text.substr(text.rfind(')') + 2));
    std::string field;
    double utime = 0, stime = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i) {
      if (i == 14) utime = std::stod(field);
      if (i == 15) stime = std::stod(field);
    }
    return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
  }
  return -1;
}

struct Submitted {
  Clock::time_point at;
  SwarmJobSpec spec;
  std::optional<double> commit_ms;
  bool final_outcome = false;  // COMMITTED, REFUSED or ABORTED came
  bool planned = false;        // PLANNED came
  bool done = false, done_in_window = true;
};

}  // namespace

nlohmann::json run_live(int robots, double seconds, double rate) {
  const int columns = static_cast<int>(std::ceil(std::sqrt(robots * 2.0)));
  const int rows = (robots + columns - 1) / columns;
  const auto file = std::filesystem::temp_directory_path() /
                    fmt::format("bench_swarm_live_{}_{}.yaml", robots, getpid());
  std::ofstream(file) << system_yaml(robots, columns);
  testing::use_programs_beside_this_one();
  fmt::print(stderr, "booting {} robots ({})\n", robots, file.string());
  testing::SystemUnderTest sys(file.string());
  if (!sys.wait_for([](const SystemState& s) { return s.state() == "running"; }, 60s)) {
    throw std::runtime_error("the system did not boot: " + sys.boot_output());
  }
  std::mutex mutex;
  std::condition_variable changed;
  std::map<unsigned long long, Submitted> jobs;
  std::map<std::string, int> not_committed;  // final refusals and aborts by reason
  std::optional<SwarmStatus> status;
  const std::string sender = "bench";
  TopicWriter<SwarmRequest, SwarmRequestPubSubType> writer(sys.participant(),
                                                           topics::swarm_request());
  TopicReader<SwarmReply, SwarmReplyPubSubType> replies(
      sys.participant(), topics::swarm_reply(), [&](const SwarmReply& r, const auto&) {
        std::lock_guard lock(mutex);
        auto it = jobs.find(r.request());
        if (r.sender() != sender || it == jobs.end()) return;
        if (r.outcome() == SWARM_PLANNED) it->second.planned = true;
        if (r.outcome() != SWARM_PLANNED) it->second.final_outcome = true;
        if (r.outcome() == SWARM_REFUSED || r.outcome() == SWARM_ABORTED) {
          const auto colon = r.reason().find(": ");  // the reason without the job's id
          fmt::print(stderr, "request {} ({} at {:.1f}, {:.1f}): {}\n", r.request(),
                     it->second.spec.id(), it->second.spec.area().x()[0] + 0.5,
                     it->second.spec.area().y()[0] + 0.5, r.reason());
          ++not_committed[colon == std::string::npos ? r.reason() : r.reason().substr(colon + 2)];
        }
        if (r.outcome() == SWARM_COMMITTED && !it->second.commit_ms) {
          it->second.commit_ms =
              std::chrono::duration<double, std::milli>(Clock::now() - it->second.at).count();
        }
      });
  TopicReader<SwarmStatus, SwarmStatusPubSubType> statuses(
      sys.participant(), topics::swarm_status(), [&](const SwarmStatus& s, const auto&) {
        std::lock_guard lock(mutex);
        status = s;
        changed.notify_all();
      });
  // Requests only once the coordinator reads them and its replies reach us (volatile topics: a
  // reply sent before the match is lost).
  for (const auto until = Clock::now() + 30s; writer.matched() == 0 || replies.matched() == 0;) {
    if (Clock::now() > until) throw std::runtime_error("no coordinator reads oscar/swarm/request");
    std::this_thread::sleep_for(10ms);
  }
  // Our side matched; the coordinator's reply writer may learn of our reader a moment later.
  std::this_thread::sleep_for(1s);
  {
    std::unique_lock lock(mutex);
    if (!changed.wait_for(lock, 60s, [&] {
          return status && status->robots().size() == static_cast<std::size_t>(robots);
        })) {
      throw std::runtime_error("not every robot joined the coordinator's planning");
    }
  }
  std::vector<std::unique_ptr<testing::CueWatch<RobotState>>> states;
  for (int i = 0; i < robots; ++i)
    states.push_back(sys.watch<RobotState>(robot_name(i) + "/state", 10000));
  auto violations = sys.watch<SafetyViolation>("safety/violations", 10000);
  std::size_t violation_count = 0;
  std::map<std::string, unsigned long long> by_job;  // job id -> request
  auto observe = [&] {
    for (auto& w : states) {
      for (const auto& s : w->take()) {
        if (s.job().id().empty()) continue;
        std::lock_guard lock(mutex);
        const auto r = by_job.find(s.job().id());
        if (r == by_job.end()) continue;
        auto& j = jobs.at(r->second);
        j.done = true;
        const auto& xs = j.spec.area().x();
        const auto& ys = j.spec.area().y();
        const bool inside = s.x() >= xs[0] - 0.05 && s.x() <= xs[1] + 0.05 &&
                            s.y() >= ys[0] - 0.05 && s.y() <= ys[2] + 0.05;
        const auto t = static_cast<std::int64_t>(s.header().stamps().front());
        if (!inside || t < j.spec.earliest_start_ns() || t > j.spec.latest_finish_ns()) {
          j.done_in_window = false;
        }
      }
    }
    violation_count += violations->take().size();
  };

  std::mt19937 rng(1);
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const double width = kSpacing * (columns - 1), height = kSpacing * std::max(1, rows - 1);
  const std::string coordinator_marker = file.string();
  const double cpu0 = cpu_seconds("oscar-coordinator", coordinator_marker);
  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(1.0 / rate);
  unsigned long long id = 0;
  fmt::print(stderr, "submitting {:.1f} jobs/s for {:.0f} s\n", rate, seconds);
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    const auto next =
        start + std::chrono::duration_cast<Clock::duration>(period * static_cast<double>(id));
    std::this_thread::sleep_until(next);
    // Between two robots' starts, so no job lies on a standing robot.
    const double x = kSpacing * (std::floor(uni(0, width / kSpacing)) + 0.5);
    const double y = kSpacing * (std::floor(uni(0, std::max(1.0, height / kSpacing))) + 0.5);
    SwarmJobSpec j;
    j.id(fmt::format("job{}", id + 1));
    j.area().x({x - 0.5, x + 0.5, x + 0.5, x - 0.5});
    j.area().y({y - 0.5, y - 0.5, y + 0.5, y + 0.5});
    const auto now = wall_now();
    j.earliest_start_ns(now + 3'000'000'000LL);
    j.latest_finish_ns(now + 60'000'000'000LL);
    j.duration_s(uni(2, 5));
    SwarmRequest r;
    r.sender(sender);
    r.id(++id);
    r.kind(SWARM_SCHEDULE);
    r.jobs().push_back(j);
    {
      std::lock_guard lock(mutex);
      jobs[id] = Submitted{Clock::now(), j, std::nullopt};
      by_job[j.id()] = id;
    }
    writer.write(r);
    observe();
  }
  const double cpu1 = cpu_seconds("oscar-coordinator", coordinator_marker);
  const double busy_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  fmt::print(stderr, "watching the robots until the last window closes (60 s)\n");
  const auto until = Clock::now() + 61s;
  while (Clock::now() < until) {
    std::this_thread::sleep_for(200ms);
    observe();
  }
  std::lock_guard lock(mutex);
  std::vector<double> latencies;
  int committed = 0, done_in_window = 0;
  std::vector<std::string> unanswered;  // requests without a final outcome, and what came
  for (const auto& [rid, j] : jobs) {
    if (!j.final_outcome) {
      unanswered.push_back(fmt::format("{} ({})", rid, j.planned ? "planned" : "no reply"));
    }
    if (j.commit_ms) {
      ++committed;
      latencies.push_back(*j.commit_ms);
      if (j.done && j.done_in_window) ++done_in_window;
    }
  }
  const SwarmStatus last = status.value_or(SwarmStatus{});
  sys.shut_down();
  std::filesystem::remove(file);
  return {{"robots", robots},
          {"jobs_submitted", jobs.size()},
          {"jobs_committed", committed},
          {"jobs_done_in_window", done_in_window},
          {"safety_violations", violation_count},
          {"submit_to_commit_ms_p50", percentile(latencies, 0.5)},
          {"submit_to_commit_ms_p99", percentile(latencies, 0.99)},
          {"naks", last.naks()},
          {"replans", last.replans()},
          {"timeouts", last.timeouts()},
          {"not_committed", not_committed},
          {"unanswered", unanswered},
          {"coordinator_cpu_percent",
           cpu0 < 0 || cpu1 < 0 ? -1.0 : 100 * (cpu1 - cpu0) / busy_seconds}};
}

}  // namespace oscar::bench
