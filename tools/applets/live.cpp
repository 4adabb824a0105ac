#include "live.hpp"

#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <oscar/coordinator.h>
#include <yaml-cpp/yaml.h>

#include "oscar/config_client.hpp"
#include "oscar/coordinator/plan_json.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/testing/booted_system.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::tools {
namespace {

namespace fs = std::filesystem;
using applets::Action;
using applets::BundleId;
using applets::ServiceId;
using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

std::atomic<bool> g_interrupted{false};

void on_signal(int) { g_interrupted = true; }

// Ctrl-C (and SIGTERM) ends the run between two waits; the system is shut down on the way out.
class SignalGuard {
 public:
  SignalGuard() {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~SignalGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

void check_interrupted() {
  if (g_interrupted) throw std::runtime_error("interrupted: the system is shut down");
}

void sleep_until(Clock::time_point t) {
  while (Clock::now() < t) {
    check_interrupted();
    std::this_thread::sleep_for(std::min<Clock::duration>(t - Clock::now(), milliseconds(20)));
  }
}

bool is_identifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  for (const char c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  }
  return true;
}

std::string module_of(const std::string& service) { return "svc_" + service; }
std::string process_of(const std::string& applet) { return "app_" + applet; }

long long scaled(milliseconds t, double scale) {
  return std::llround(static_cast<double>(t.count()) * scale);
}

// The features of a scenario the live system cannot reproduce, before anything starts.
void refuse_what_cannot_run(const applets::Scenario& scenario, const LiveOptions& options) {
  const auto& m = scenario.system().model;
  if (!(options.time_scale > 0)) {
    throw std::invalid_argument(
        fmt::format("--time-scale must be above 0, not {}", options.time_scale));
  }
  for (const auto& s : m.services()) {
    if (!s.provider && !is_identifier(s.name)) {
      throw std::invalid_argument(fmt::format(
          "service '{}': --live needs service names that are identifiers (letters, digits, _): "
          "a stand-in module '{}' provides it",
          s.name, module_of(s.name)));
    }
  }
  for (const auto& a : m.applets()) {
    if (!is_identifier(a.name)) {
      throw std::invalid_argument(fmt::format(
          "applet '{}': --live needs applet names that are identifiers (letters, digits, _): "
          "it runs in a process '{}'",
          a.name, process_of(a.name)));
    }
  }
  for (const auto& step : scenario.steps()) {
    for (const auto& a : step.actions) {
      if (a.kind == Action::Kind::kCrash && !m.applet(a.applet).provides.empty()) {
        throw std::invalid_argument(fmt::format(
            "{}: crash of service applet '{}' cannot be reproduced --live: the coordinator "
            "releases the bundles of a crashed applet in another process but does not make the "
            "services it provides unavailable (offline they are)",
            a.where, m.applet(a.applet).name));
      }
    }
  }
}

// The coordinator's plan as it publishes it, and when it last changed.
class PlanWatch {
 public:
  explicit PlanWatch(DdsParticipant& participant)
      : reader_(participant, topics::applet_plan(), [this](const AppletPlan& p, const auto&) {
          std::lock_guard lock(mutex_);
          plan_ = p;
          changed_at_ = Clock::now();
          changed_.notify_all();
        }) {}

  std::optional<AppletPlan> latest() {
    std::lock_guard lock(mutex_);
    return plan_;
  }

  /// Waits until a plan satisfies `pred`.
  bool wait_for(const std::function<bool(const AppletPlan&)>& pred, Clock::duration timeout) {
    const auto until = Clock::now() + timeout;
    std::unique_lock lock(mutex_);
    while (!(plan_ && pred(*plan_))) {
      lock.unlock();
      check_interrupted();
      lock.lock();
      if (Clock::now() >= until) return false;
      changed_.wait_for(lock, milliseconds(20));
    }
    return true;
  }

  /// Waits until the plan has not changed for `quiet` since `since` (or since its last change),
  /// and returns it. nullopt if it does not settle within `timeout`.
  std::optional<AppletPlan> settled(Clock::time_point since, milliseconds quiet,
                                    Clock::duration timeout) {
    const auto until = Clock::now() + timeout;
    std::unique_lock lock(mutex_);
    for (;;) {
      const auto last = std::max(since, changed_at_);
      if (plan_ && Clock::now() - last >= quiet) return plan_;
      if (Clock::now() >= until) return std::nullopt;
      lock.unlock();
      check_interrupted();
      lock.lock();
      changed_.wait_for(lock, milliseconds(10));
    }
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<AppletPlan> plan_;
  Clock::time_point changed_at_{};
  TopicReader<AppletPlan, AppletPlanPubSubType> reader_;  // last: uses the rest
};

// A temporary folder for the system file, removed however the run ends.
class TempDir {
 public:
  TempDir() {
    std::string p = (fs::temp_directory_path() / "oscar-applets-live-XXXXXX").string();
    if (!mkdtemp(p.data())) throw std::runtime_error("cannot make a temporary folder " + p);
    path_ = p;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

const ServicePlan* find(const AppletPlan& plan, const std::string& service) {
  for (const auto& s : plan.services()) {
    if (s.name() == service) return &s;
  }
  return nullptr;
}

}  // namespace

std::string live_system_yaml(const applets::Scenario& scenario, const std::string& name,
                             const LiveOptions& options) {
  refuse_what_cannot_run(scenario, options);
  const auto& config = scenario.system();
  const auto& m = config.model;
  const double k = options.time_scale;
  YAML::Emitter y;
  y << YAML::BeginMap;
  y << YAML::Key << "system" << YAML::Value << name;
  y << YAML::Key << "modules" << YAML::Value << YAML::BeginSeq;
  for (const auto& s : m.services()) {
    if (s.provider) continue;
    const auto module = module_of(s.name);
    y << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << module;
    y << YAML::Key << "kernels" << YAML::Value << YAML::BeginSeq << YAML::BeginMap;
    y << YAML::Key << "type" << YAML::Value << "bench_source";
    y << YAML::Key << "name" << YAML::Value << module << YAML::EndMap << YAML::EndSeq;
    y << YAML::Key << "mode" << YAML::Value << "deactivated" << YAML::EndMap;
  }
  y << YAML::EndSeq;
  y << YAML::Key << "services" << YAML::Value << YAML::BeginMap;
  for (const auto& s : m.services()) {
    y << YAML::Key << s.name << YAML::Value << YAML::BeginMap;
    if (!s.provider) {
      y << YAML::Key << "provided_by" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << module_of(s.name) << YAML::EndSeq;
      y << YAML::Key << "granted" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "activate" << YAML::Value << "continuous:1s" << YAML::EndMap;
      y << YAML::Key << "idle" << YAML::Value << "deactivate";
    }
    y << YAML::Key << "access" << YAML::Value << (s.exclusive_only ? "exclusive" : "shared");
    y << YAML::Key << "needs" << YAML::Value << YAML::BeginSeq;
    for (const auto& d : s.dependencies) {
      y << YAML::Flow << YAML::BeginMap << YAML::Key << "service" << YAML::Value
        << m.service(d.service).name << YAML::Key << "access" << YAML::Value
        << (d.access == applets::Access::kShared ? "shared" : "exclusive") << YAML::EndMap;
    }
    y << YAML::EndSeq << YAML::EndMap;
  }
  y << YAML::EndMap;
  y << YAML::Key << "coordinator" << YAML::Value << YAML::BeginMap;
  const auto& o = config.options;
  y << YAML::Key << "scheduler" << YAML::Value << YAML::Flow << YAML::BeginMap;
  y << YAML::Key << "context_switch_ms" << YAML::Value << scaled(o.context_switch, k);
  y << YAML::Key << "revoke_wait_ms" << YAML::Value << scaled(o.revoke_wait, k);
  y << YAML::Key << "negotiation_round_ms" << YAML::Value << scaled(o.negotiation_round_max, k);
  y << YAML::Key << "negotiation_rounds" << YAML::Value << o.negotiation_rounds_max;
  y << YAML::EndMap;
  // Generous: a missed beat on a loaded machine must not take an applet's bundles mid-scenario.
  y << YAML::Key << "applet_lease" << YAML::Value << "5s";
  y << YAML::Key << "applets" << YAML::Value << YAML::BeginSeq;
  std::set<BundleId> at_start(config.requested_at_start.begin(), config.requested_at_start.end());
  for (const auto& a : m.applets()) {
    y << YAML::BeginMap;
    y << YAML::Key << "type" << YAML::Value << "event_applet";
    y << YAML::Key << "name" << YAML::Value << a.name;
    y << YAML::Key << "process" << YAML::Value << process_of(a.name);
    y << YAML::Key << "fail_stop" << YAML::Value << a.fail_stop;
    y << YAML::Key << "provides" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const ServiceId s : a.provides) y << m.service(s).name;
    y << YAML::EndSeq;
    y << YAML::Key << "params" << YAML::Value << YAML::BeginMap;
    if (const auto it = config.applet_params.find(a.name); it != config.applet_params.end()) {
      for (const auto& [key, value] : it->second) {
        if (key != "auto_yield") y << YAML::Key << key << YAML::Value << value;
      }
    }
    y << YAML::Key << "auto_yield" << YAML::Value << (scenario.auto_yield() ? "true" : "false");
    y << YAML::EndMap;
    y << YAML::Key << "bundles" << YAML::Value << YAML::BeginSeq;
    for (const BundleId b : a.bundles) {
      const auto& bundle = m.bundle(b);
      y << YAML::BeginMap << YAML::Key << "name" << YAML::Value << bundle.name;
      y << YAML::Key << "priority" << YAML::Value << bundle.priority;
      if (at_start.contains(b)) y << YAML::Key << "requested" << YAML::Value << true;
      y << YAML::Key << "resources" << YAML::Value << YAML::BeginSeq;
      for (const auto r : bundle.resources) {
        const auto& res = m.resource(r);
        y << YAML::Flow << YAML::BeginMap << YAML::Key << "service" << YAML::Value
          << m.service(res.service).name << YAML::Key << "access" << YAML::Value
          << (res.access == applets::Access::kShared ? "shared" : "exclusive") << YAML::EndMap;
      }
      y << YAML::EndSeq << YAML::EndMap;
    }
    y << YAML::EndSeq << YAML::EndMap;
  }
  y << YAML::EndSeq << YAML::EndMap << YAML::EndMap;
  return std::string(y.c_str()) + "\n";
}

std::vector<applets::StepResult> run_live(const applets::Scenario& scenario,
                                          const std::string& file, const LiveOptions& options) {
  const auto stem = fs::path(file).stem().string();
  std::string system_name = "live_";
  for (const char c : stem) system_name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  const auto yaml = live_system_yaml(scenario, system_name, options);
  const auto& config = scenario.system();
  const auto& m = config.model;
  for (const auto& [service, params] : config.service_params) {
    if (params.empty()) continue;
    std::fprintf(stderr,
                 "oscar applets run --live: service %s: its params are kept for the service "
                 "only (the plan does not read them, nor does its stand-in module)\n",
                 service.c_str());
  }

  SignalGuard signals;
  g_interrupted = false;
  TempDir dir;
  const auto system_file = (dir.path() / (system_name + ".yaml")).string();
  std::ofstream(system_file) << yaml;
  SystemSpec::load(system_file);  // what boot checks, before anything starts
  testing::use_programs_beside_this_one();

  std::size_t modules = 0;
  for (const auto& s : m.services()) modules += s.provider ? 0 : 1;
  std::fprintf(stderr,
               "oscar applets run --live: booting %zu stand-in module(s) and %zu applet "
               "process(es)...\n",
               modules, m.applets().size());
  testing::SystemUnderTest sys(
      system_file, {.domain = -1, .boot_timeout = std::chrono::seconds(60), .log_dir = ""});
  std::fprintf(stderr, "oscar applets run --live: system %s on domain %d\n", system_name.c_str(),
               sys.domain());
  // Both read through the system's participant: gone before the system shuts down.
  std::optional<PlanWatch> watch(std::in_place, sys.participant());
  std::optional<ConfigClient> sender(std::in_place, sys.participant(), "boot");
  auto& plans = *watch;
  auto& operator_ = *sender;
  if (auto running = sys.wait_until_running({}, std::chrono::seconds(90)); !running) {
    throw std::runtime_error(std::string("the system did not start: ") + running.message());
  }
  check_interrupted();
  std::fprintf(stderr, "oscar applets run --live: every module runs; waiting for the applets\n");
  const bool announced = plans.wait_for(
      [&](const AppletPlan& p) {
        if (p.applets().size() != m.applets().size()) return false;
        for (const auto& a : p.applets()) {
          if (a.state() == "absent") return false;
        }
        return true;
      },
      std::chrono::seconds(60));
  if (!announced) {
    throw std::runtime_error("the applets did not announce themselves to the coordinator");
  }
  const auto ready = plans.settled(Clock::now(), options.settle, std::chrono::seconds(30));
  if (!ready) throw std::runtime_error("the coordinator's plan did not settle after the start");
  std::fprintf(stderr, "oscar applets run --live: every applet announced; running the timeline\n");

  // The scenario's clock: t = 0 now; the coordinator's clock (deadlines) at t = 0.
  const auto t0 = Clock::now();
  const auto stamp_age = std::chrono::duration_cast<milliseconds>(std::chrono::nanoseconds(
      static_cast<long long>(wall_now()) - static_cast<long long>(ready->stamp_ns())));
  const long long c0 = ready->clock_ms() + stamp_age.count();
  const double k = options.time_scale;
  const auto real = [&](milliseconds t) {
    return t0 + std::chrono::duration_cast<Clock::duration>(
                    std::chrono::duration<double, std::milli>(static_cast<double>(t.count()) * k));
  };

  auto send = [&](const Action& a, AppletEvent e) {
    const auto reply =
        operator_.command("coordinator", "coordinator", "applet", e, std::chrono::seconds(10));
    if (!reply.ok()) {
      throw std::invalid_argument(fmt::format("{}: {} {}/{} refused live: {}", a.where, e.event(),
                                              e.applet(), e.bundle(), reply.error()));
    }
  };
  auto event_for = [&](const Action& a, const char* what) {
    AppletEvent e;
    e.event(what);
    if (what == std::string("crash")) {
      e.applet(m.applet(a.applet).name);
    } else {
      e.applet(m.applet(m.bundle(a.bundle).applet).name);
      e.bundle(m.bundle(a.bundle).name);
    }
    return e;
  };

  std::vector<applets::StepResult> out;
  milliseconds clock{0};
  for (const auto& step : scenario.steps()) {
    if (step.t) clock = std::max(clock, *step.t);
    sleep_until(real(clock));
    for (const auto& a : step.actions) {
      switch (a.kind) {
        case Action::Kind::kRequest:
          send(a, event_for(a, "request"));
          if (a.trigger) send(a, event_for(a, "trigger"));
          break;
        case Action::Kind::kRelease:
          send(a, event_for(a, "release"));
          break;
        case Action::Kind::kYield:
          send(a, event_for(a, "yield"));
          break;
        case Action::Kind::kTrigger:
          send(a, event_for(a, "trigger"));
          break;
        case Action::Kind::kSetPriority: {
          auto e = event_for(a, "set_priority");
          e.priority(a.priority);
          send(a, e);
          break;
        }
        case Action::Kind::kSetDeadline: {
          auto e = event_for(a, "set_deadline");
          e.has_deadline(a.deadline.has_value());
          if (a.deadline) {
            e.t_early_ms(c0 + scaled(a.deadline->t_early, k));
            e.t_duration_ms(scaled(a.deadline->t_duration, k));
            e.t_finish_ms(c0 + scaled(a.deadline->t_finish, k));
          }
          send(a, e);
          break;
        }
        case Action::Kind::kCrash:
          send(a, event_for(a, "crash"));
          break;
        case Action::Kind::kAdvance:
          clock += a.advance;
          sleep_until(real(clock));
          break;
        case Action::Kind::kNegotiate: {
          auto e = event_for(a, "negotiate");
          e.min_ms(scaled(a.negotiation.min_needed, k));
          e.max_ms(scaled(a.negotiation.max_needed, k));
          e.accept(a.negotiation.accept);
          send(a, e);
          break;
        }
      }
    }
    const auto plan = plans.settled(Clock::now(), options.settle, std::chrono::seconds(30));
    if (!plan) {
      throw std::runtime_error(fmt::format("{}: the plan did not settle within 30 s", step.where));
    }
    applets::StepResult r;
    r.label = step.label;
    r.t = clock;
    for (const auto& s : m.services()) {
      const auto* p = find(*plan, s.name);
      r.holders.emplace_back(s.name, p ? p->plan() : "?");
      r.active.emplace_back(s.name, p ? p->active() : "?");
    }
    auto got = [](const auto& list, const std::string& service) {
      for (const auto& [s, h] : list) {
        if (s == service) return h;
      }
      return std::string("?");
    };
    for (const auto& [svc, want] : step.expect) {
      const auto holder = got(r.holders, svc);
      if (holder != want) {
        r.mismatches.push_back(step.where + ": '" + step.label + "': service " + svc +
                               ": expected " + want + ", got " + holder);
      }
    }
    for (const auto& [svc, want] : step.expect_active) {
      const auto holder = got(r.active, svc);
      if (holder != want) {
        r.mismatches.push_back(step.where + ": '" + step.label + "': service " + svc +
                               " in use by: expected " + want + ", got " + holder);
      }
    }
    std::fprintf(stderr, "oscar applets run --live: step '%s' done\n", step.label.c_str());
    out.push_back(std::move(r));
  }
  std::fprintf(stderr, "oscar applets run --live: shutting the system down\n");
  sender.reset();
  watch.reset();
  const auto shut = sys.shut_down();
  if (!sys.leftover_processes().empty()) {
    std::fprintf(stderr, "oscar applets run --live: %zu process(es) of the system were left\n",
                 sys.leftover_processes().size());
  }
  (void)shut;
  return out;
}

}  // namespace oscar::tools
