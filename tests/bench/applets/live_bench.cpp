// oscar-bench-applets --live: the applet scheduler in a booted system, applets in processes of
// their own (docs/benchmarks-applets.md). Per run: a framegrabber module provides the exclusive
// service Camera; applets `low` and `high` (frame_mode_switcher, each in a process of its own)
// hold it in turn, and N-2 idle applets in the coordinator hold a shared service, so that every
// plan covers N applets. Each round:
//   grant:   the operator's event "low: request" sent -> the framegrabber's reply to the
//            coordinator's activate (it runs now);
//   preempt: "high: request" sent -> low interrupted, yields -> high granted -> high's first
//            command (frame mode half) accepted by the framegrabber;
// then both release. Times are taken in this process when it sends the event and when the
// module's reply arrives (oscar/config_reply/cam): the event's own way to the applet's process
// (two hops) is included, so the figures bound the applet's call from above.
#include "live_bench.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <oscar/config.h>
#include <oscar/coordinator.h>
#include <nlohmann/json.hpp>

#include "oscar/config_client.hpp"
#include "oscar/coordinator/plan_json.hpp"  // AppletEvent as a command port's request
#include "oscar/testing/booted_system.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr const char* kModule = "cam";
constexpr milliseconds kWait{10000};  // for anything one round waits for

std::string system_yaml(int applets) {
  std::string y = fmt::format(R"(system: bench_applets_live
modules:
  - name: {0}
    kernels:
      - {{ type: framegrabber, name: {0}, params: {{ source: "synthetic:static", width: 64, height: 48 }} }}
    mode: deactivated
)",
                              kModule);
  const int idle = applets - 2;
  if (idle > 0) {
    y += "  - { name: display, kernels: [ { type: bench_source, name: display } ], "
         "mode: deactivated }\n";
  }
  y += fmt::format(R"(services:
  Camera:
    provided_by: [{}]
    access: exclusive
    granted: {{ activate: "continuous:1s" }}
    idle: deactivate
)",
                   kModule);
  if (idle > 0) {
    y += "  Display: { provided_by: [display], granted: { activate: \"continuous:1s\" }, "
         "idle: deactivate }\n";
  }
  // A generous lease: a missed beat on a loaded machine must not take a bundle mid-round.
  y += "coordinator:\n  scheduler: { context_switch_ms: 0, revoke_wait_ms: 1000 }\n"
       "  applet_lease: 5s\n  applets:\n";
  for (const char* who : {"low", "high"}) {
    y += fmt::format(
        "    - type: frame_mode_switcher\n      name: {0}\n      process: bench_{0}\n"
        "      params: {{ module: {1}, modes: {2}, switch_every_ms: 1 }}\n"
        "      bundles: [ {{ name: camera, priority: {0}, resources: [ {{ service: Camera }} ] "
        "}} ]\n",
        who, kModule, who == std::string("low") ? "quarter" : "half");
  }
  for (int i = 0; i < idle; ++i) {
    y += fmt::format(
        "    - {{ type: event_applet, name: idle{}, params: {{ period_ms: 1000 }}, bundles: [ {{ "
        "name: display, priority: low, requested: true, resources: [ {{ service: Display, "
        "access: shared }} ] }} ] }}\n",
        i);
  }
  return y;
}

// The module's replies as they arrive here, with their time of arrival.
class ReplyWatch {
 public:
  using Pred = std::function<bool(const ConfigReply&)>;
  ReplyWatch(DdsParticipant& participant, const std::string& module)
      : reader_(participant, topics::config_reply(module),
                [this](const ConfigReply& r, const auto&) {
                  const auto now = Clock::now();
                  std::lock_guard lock(mutex_);
                  replies_.emplace_back(now, r);
                  arrived_.notify_all();
                }) {}

  /// When the first reply after `since` satisfying `pred` arrived.
  /// @throws std::runtime_error naming `what` if none does within kWait.
  Clock::time_point first(Clock::time_point since, const Pred& pred, const char* what) {
    std::unique_lock lock(mutex_);
    while (!replies_.empty() && replies_.front().first < since) replies_.pop_front();
    std::size_t seen = 0;
    const auto until = Clock::now() + kWait;
    for (;;) {
      for (; seen < replies_.size(); ++seen) {
        if (pred(replies_[seen].second)) return replies_[seen].first;
      }
      if (arrived_.wait_until(lock, until) == std::cv_status::timeout && seen == replies_.size()) {
        throw std::runtime_error(fmt::format("the framegrabber did not reply: {}", what));
      }
    }
  }

 private:
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<std::pair<Clock::time_point, ConfigReply>> replies_;
  TopicReader<ConfigReply, ConfigReplyPubSubType> reader_;  // last: uses the rest
};

// The coordinator's plans: the latest, and the compute times of those published while recording.
class PlanWatch {
 public:
  explicit PlanWatch(DdsParticipant& participant)
      : reader_(participant, topics::applet_plan(), [this](const AppletPlan& p, const auto&) {
          std::lock_guard lock(mutex_);
          if (recording_) plan_us_.push_back(p.plan_us());
          latest_ = p;
          changed_.notify_all();
        }) {}

  bool wait_for(const std::function<bool(const AppletPlan&)>& pred, Clock::duration timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return latest_ && pred(*latest_); });
  }
  void record() {
    std::lock_guard lock(mutex_);
    recording_ = true;
  }
  std::vector<double> plan_us() {
    std::lock_guard lock(mutex_);
    return plan_us_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<AppletPlan> latest_;
  bool recording_ = false;
  std::vector<double> plan_us_;
  TopicReader<AppletPlan, AppletPlanPubSubType> reader_;  // last: uses the rest
};

bool runs(const ConfigReply& r, const std::string& mode) {
  if (!r.ok()) return false;
  for (const auto& k : r.state().kernels()) {
    if (k.name() == kModule) return k.mode() == mode;
  }
  return false;
}

bool switched_to(const ConfigReply& r, const std::string& frame_mode) {
  const auto& a = r.answer();
  const auto tail = "-> " + frame_mode;
  return r.ok() && r.answered() && a.size() >= tail.size() &&
         a.compare(a.size() - tail.size(), tail.size(), tail) == 0;
}

double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

struct Run {
  int applets = 0, grants = 0;
  double grant_p50 = 0, grant_p99 = 0, preempt_p50 = 0, preempt_p99 = 0;
  double plan_us_p50 = 0;
  std::size_t plans = 0;
};

Run measure(int applets, int grants) {
  const auto dir = fs::temp_directory_path() / fmt::format("oscar-bench-applets-{}", getpid());
  fs::create_directories(dir);
  struct RemovedAtTheEnd {  // however the run ends; after the system's shutdown
    fs::path dir;
    ~RemovedAtTheEnd() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } removed{dir};
  const auto file = (dir / "system.yaml").string();
  std::ofstream(file) << system_yaml(applets);
  std::fprintf(stderr, "oscar bench applets --live: booting a system with %d applets...\n",
               applets);
  testing::SystemUnderTest sys(
      file, {.domain = -1, .boot_timeout = std::chrono::seconds(120), .log_dir = ""});
  std::optional<ReplyWatch> replies(std::in_place, sys.participant(), kModule);
  std::optional<PlanWatch> plans(std::in_place, sys.participant());
  std::optional<ConfigClient> operator_(std::in_place, sys.participant(), "boot");
  if (auto ok = sys.wait_until_running({}, std::chrono::seconds(120)); !ok) {
    throw std::runtime_error(std::string("the system did not start: ") + ok.message());
  }
  const bool ready = plans->wait_for(
      [&](const AppletPlan& p) {
        if (static_cast<int>(p.applets().size()) != applets) return false;
        for (const auto& a : p.applets()) {
          if (a.state() == "absent" || (a.name().rfind("idle", 0) == 0 && a.state() != "holding")) {
            return false;
          }
        }
        return true;
      },
      std::chrono::seconds(120));
  if (!ready) throw std::runtime_error("the applets did not all announce themselves in 120 s");

  auto event = [&](const char* applet, const char* what) {
    AppletEvent e;
    e.applet(applet);
    e.bundle("camera");
    e.event(what);
    const auto r = operator_->command("coordinator", "coordinator", "applet", e, kWait);
    if (!r.ok()) throw std::runtime_error(fmt::format("{} {}: {}", applet, what, r.error()));
  };
  std::vector<double> grant, preempt;
  // Round -1 warms up (the first activation and commands after boot are slower) and is not
  // counted.
  for (int i = -1; i < grants; ++i) {
    if (i == 0) plans->record();
    auto t0 = Clock::now();
    event("low", "request");
    grant.push_back(
        ms(replies->first(
               t0, [](const auto& r) { return runs(r, "continuous"); }, "activate for low") -
           t0));
    replies->first(
        t0, [](const auto& r) { return switched_to(r, "quarter"); }, "low's command");
    t0 = Clock::now();
    event("high", "request");
    preempt.push_back(
        ms(replies->first(
               t0, [](const auto& r) { return switched_to(r, "half"); }, "high's command") -
           t0));
    t0 = Clock::now();
    event("high", "release");
    replies->first(
        t0, [](const auto& r) { return switched_to(r, "quarter"); }, "low's again");
    t0 = Clock::now();
    event("low", "release");
    replies->first(
        t0, [](const auto& r) { return runs(r, "deactivated"); }, "deactivate");
    if (i < 0) {
      grant.clear();
      preempt.clear();
    } else if ((i + 1) % 100 == 0 || i + 1 == grants) {
      std::fprintf(stderr, "oscar bench applets --live: %d applets: %d of %d grants\n", applets,
                   i + 1, grants);
    }
  }
  Run run;
  run.applets = applets;
  run.grants = grants;
  run.grant_p50 = percentile(grant, 0.5);
  run.grant_p99 = percentile(grant, 0.99);
  run.preempt_p50 = percentile(preempt, 0.5);
  run.preempt_p99 = percentile(preempt, 0.99);
  const auto us = plans->plan_us();
  run.plans = us.size();
  run.plan_us_p50 = percentile(us, 0.5);
  operator_.reset();
  plans.reset();
  replies.reset();
  sys.shut_down();
  return run;
}

}  // namespace

int run_live_bench(const LiveBenchOptions& options) {
  if (options.grants < 1 || options.applets.empty()) {
    std::cerr << "oscar bench applets --live: needs --grants >= 1 and at least one --applets\n";
    return 2;
  }
  for (const int n : options.applets) {
    if (n < 2) {
      std::cerr << "oscar bench applets --live: --applets " << n
                << ": a run needs at least the 2 applets it measures\n";
      return 2;
    }
  }
  testing::use_programs_beside_this_one();
  std::vector<Run> runs;
  try {
    for (const int n : options.applets) runs.push_back(measure(n, options.grants));
  } catch (const std::exception& e) {
    // Caught here, so that the booted system is shut down on the way (nothing left behind).
    std::cerr << "oscar bench applets --live: " << e.what() << "\n";
    return 1;
  }
  if (options.json) {
    nlohmann::ordered_json j;
    j["grant_ms_p50"] = runs.front().grant_p50;
    j["grant_ms_p99"] = runs.front().grant_p99;
    j["preempt_ms_p50"] = runs.front().preempt_p50;
    j["preempt_ms_p99"] = runs.front().preempt_p99;
    j["applets"] = runs.front().applets;
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (const auto& r : runs) {
      all.push_back({{"applets", r.applets},
                     {"grants", r.grants},
                     {"grant_ms_p50", r.grant_p50},
                     {"grant_ms_p99", r.grant_p99},
                     {"preempt_ms_p50", r.preempt_p50},
                     {"preempt_ms_p99", r.preempt_p99},
                     {"plan_us_p50", r.plan_us_p50}});
    }
    j["runs"] = all;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf(
      "applets across processes: low and high each in a process of its own, the other applets "
      "idle in the coordinator\n"
      "  %8s %7s %14s %9s %16s %9s %12s %7s\n",
      "applets", "grants", "grant_ms p50", "p99", "preempt_ms p50", "p99", "plan_us p50", "plans");
  for (const auto& r : runs) {
    std::printf("  %8d %7d %14.2f %9.2f %16.2f %9.2f %12.1f %7zu\n", r.applets, r.grants,
                r.grant_p50, r.grant_p99, r.preempt_p50, r.preempt_p99, r.plan_us_p50, r.plans);
  }
  return 0;
}

}  // namespace oscar::bench
