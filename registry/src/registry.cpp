// The registry's events: monitors, process events, module announcements and heartbeats,
// requests, and what a failure sets off (the actions are in registry_actions.cpp).
#include "oscar/registry/registry.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "oscar/time.hpp"
#include "registry_io.hpp"
#include "registry_tracked.hpp"
#include "start_order.hpp"

namespace oscar {
namespace {

// The longest sender or module name a registry request may carry.
constexpr std::size_t kMaxRequestNameChars = 256;

}  // namespace

Registry::Registry(const SystemSpec& system, DdsParticipant& participant, std::string journal_file,
                   bool recovering)
    : system_(system),
      participant_(participant),
      config_(participant, "registry"),
      state_(recovering ? "recovering" : "booting"),
      recovering_(recovering),
      recovery_since_(Clock::now()),
      journal_file_(std::move(journal_file)),
      wall_at_start_ns_(wall_now()),
      port_file_watch_(participant.shared_memory_port()) {
  for (const auto& m : system_.modules) {
    auto t = std::make_unique<Tracked>();
    t->spec = &m;
    t->status = m.standby ? "standby" : "waiting";
    modules_.push_back(std::move(t));
  }
  const auto first = internal::producers_launched_first(system_);
  for (std::size_t i = 0; i < modules_.size(); ++i) {
    for (auto p : first[i]) modules_[i]->launched_after.push_back(modules_[p].get());
  }
  if (recovering_) read_journal();
  io_ = std::make_unique<Io>(*this);
}

Registry::~Registry() { io_.reset(); }

void Registry::post(std::function<void()> event) {
  std::lock_guard lock(mutex_);
  events_.push_back(std::move(event));
  wake_.notify_all();
}

void Registry::stop() {
  std::lock_guard lock(mutex_);
  stop_requested_ = true;
  wake_.notify_all();
}

bool Registry::run() {
  spdlog::info("registry: system '{}' with {} modules on {} hosts, domain {}{}", system_.name,
               modules_.size(), system_.hosts.size(), system_.domain,
               recovering_ ? "; recovering after a crash: adopting what the monitors run" : "");
  if (recovering_) message_ = "a registry before this one died: adopting what the monitors run";
  publish();
  auto next_port_look = Clock::now() + std::chrono::seconds(1);
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait_for(lock, std::chrono::milliseconds(10),
                   [&] { return stop_requested_ || !events_.empty(); });
    if (stop_requested_) break;
    run_events(lock);
    if (shutting_down_) break;
    lock.unlock();
    tick();
    if (Clock::now() >= next_port_look) {
      next_port_look = Clock::now() + std::chrono::seconds(1);
      if (const auto lost = port_file_watch_.lost()) {
        spdlog::error(
            "registry: ending and leaving the system running: its shared-memory port {} was "
            "removed or replaced by another process (systemd-logind's RemoveIPC does so at the "
            "end of the user's last session, see docs/boot.md), so a process that starts from "
            "now on could not reach it; boot starts another registry, which adopts the system",
            *lost);
        return false;
      }
    }
    lock.lock();
  }
  lock.unlock();
  shutdown();
  return true;
}

void Registry::run_events(std::unique_lock<std::mutex>& lock) {
  while (!events_.empty()) {
    auto event = std::move(events_.front());
    events_.pop_front();
    lock.unlock();
    event();
    lock.lock();
  }
}

Registry::Tracked* Registry::find(const std::string& name) {
  for (auto& m : modules_) {
    if (m->spec->spec.name == name) return m.get();
  }
  return nullptr;
}

void Registry::on_monitor_beat(const MonitorBeat& beat) {
  auto& mon = monitors_[beat.host()];
  if (mon.alive && mon.pid == beat.pid()) return;
  const bool back = !mon.alive && mon.pid != 0;
  mon = Monitor{beat.pid(), true, beat.log_dir()};
  spdlog::info("registry: monitor of host '{}' is {} (pid {})", beat.host(), back ? "back" : "up",
               beat.pid());
  for (auto& m : modules_) {
    if (m->spec->spec.host != beat.host() || m->process_gone || m->incarnation == 0) continue;
    if (m->status == "running" && m->spec->debug.holds_process() && m->launched_by != beat.pid()) {
      // Its heartbeat did not count (on_module_lost): it died with the monitor that started it.
      fail(*m,
           fmt::format("host '{}' lost (its monitor, pid {}, was replaced)", beat.host(),
                       m->launched_by),
           true);
      continue;
    }
    if (m->status == "running" || m->status == "starting") continue;
    if (m->launched_by == beat.pid()) {
      // The monitor was only slow: a failed module of it may still run. Kill it; the restart
      // follows its reported exit.
      io_->send(LAUNCH_KILL, beat.host(), beat.pid(), m->spec->spec.name, m->incarnation);
    } else {
      m->process_gone = true;  // it died with its monitor (PR_SET_PDEATHSIG)
    }
  }
  publish();
}

// A lapsed monitor means the registry cannot start or stop anything on that host for now. Its
// modules are judged by their own heartbeats: if the host is really gone, or the monitor died
// (its modules die with it), those lapse too and the modules fail as "host lost".
void Registry::on_monitor_lost(const std::string& host, long pid) {
  auto it = monitors_.find(host);
  if (it == monitors_.end() || !it->second.alive || it->second.pid != pid) return;
  it->second.alive = false;
  spdlog::error("registry: host '{}' lost (its monitor, pid {}, stopped answering)", host, pid);
  for (auto& m : modules_) {
    if (m->spec->spec.host == host && m->status == "restarting" &&
        m->last_failure.find("heartbeat lost") != std::string::npos) {
      m->last_failure = fmt::format("host '{}' lost ({})", host, m->last_failure);
    }
  }
  resume_if_whole();  // its modules that failed first no longer hold the rest (on_lost)
  publish();
}

void Registry::on_process_event(const ProcessEvent& e) {
  auto* m = find(e.module_name());
  if (m && recovering_ && m->status == "waiting") {
    // A replay of what happened before the crash: the next start counts on from it.
    m->incarnation = std::max(m->incarnation, static_cast<unsigned>(e.incarnation()));
    return;
  }
  if (!m || e.incarnation() != m->incarnation) return;  // an earlier incarnation's news
  if (e.kind() == PROC_STARTED) {
    m->pid = e.pid();
    return;
  }
  m->process_gone = true;
  if (shutting_down_) {
    m->status = "stopped";
    return;
  }
  if (m->status != "running" && m->status != "starting") return;  // already handled
  // Under gdbserver the monitor's child is gdbserver: it exits (code 0) when the module ends,
  // however that was; its last line says how ("Child terminated with signal = 0xb (SIGSEGV)").
  const std::string who = m->spec->debug.holds_process() ? "gdbserver " : "";
  std::string reason = e.kind() == PROC_START_FAILED ? "could not start: " + e.detail()
                       : e.signal() != 0 ? fmt::format("{}killed by signal {}", who, e.signal())
                                         : fmt::format("{}exited with code {}", who, e.exit_code());
  if (e.kind() == PROC_EXITED && !e.detail().empty()) {
    const auto last = e.detail().substr(e.detail().rfind('\n') + 1);
    if (!last.empty()) reason += " (last output: " + last + ")";
  }
  fail(*m, reason, true);
}

void Registry::on_module_lost(const std::string& module, unsigned incarnation) {
  auto* m = find(module);
  if (!m || shutting_down_ || incarnation != m->incarnation || m->status != "running") return;
  const auto beat = io_->last_beat(module, incarnation);
  // Fast DDS 2.9's liveliness timer now and then reports a writer lost right after its
  // heartbeat came (its timer moves on to another writer meanwhile; seen 92-99 ms after a beat
  // with a 300 ms lease). Such a report is ignored; tick() still sees a real lapse. (A real one
  // comes a lease after the last beat, give or take the timer's millisecond.)
  if (beat != Clock::time_point{} && Clock::now() - beat < system_.lease / 2) return;
  const auto& host = m->spec->spec.host;
  // Under gdbserver a silent module is most likely stopped at a breakpoint: no hang, and killing
  // it would end the debugging session. Its exit or crash still ends gdbserver, which its monitor
  // reports (on_process_event); if the monitor itself dies, a new one tells (on_monitor_beat).
  // Not "only while the monitor answers": a module stopped in gdb made its monitor's heartbeat
  // lapse here for a moment too (tests/integration/debugger_test.cpp), which would kill it.
  if (m->spec->debug.holds_process()) {
    if (!m->held) {
      m->held = true;
      spdlog::info(
          "registry: module '{}' sends no heartbeat; it runs under {} (stopped in the "
          "debugger?), so it is not taken for hung",
          module, m->spec->debug.describe());
    }
    return;
  }
  const auto reason = fmt::format(
      "heartbeat lost for {} (hung or stopped; {})", format_duration(system_.lease),
      beat == Clock::time_point{}
          ? std::string("no heartbeat arrived")
          : fmt::format("last one {} ago",
                        format_duration(std::chrono::duration_cast<std::chrono::milliseconds>(
                            Clock::now() - beat))));
  fail(*m, monitors_[host].alive ? reason : fmt::format("host '{}' lost ({})", host, reason),
       false);
}

void Registry::on_module_state(const ModuleState& s) {
  auto* m = find(s.module_name());
  if (m && recovering_ &&
      (m->status == "waiting" || (m->status == "restarting" && s.incarnation() > m->incarnation))) {
    // A running module's state, replayed before its monitor's report: kept for the adoption.
    auto& early = early_[s.module_name()];
    if (s.incarnation() >= early.incarnation()) early = s;
    return;
  }
  if (!m || s.incarnation() != m->incarnation) return;
  const auto now = Clock::now();
  std::uint64_t published = 0;
  for (const auto& k : s.kernels()) published += k.published();
  if (m->has_state && now > m->rate_since + std::chrono::milliseconds(500)) {
    const double dt = std::chrono::duration<double>(now - m->rate_since).count();
    m->cues_per_s = static_cast<double>(published - std::min(published, m->rate_published)) / dt;
    m->rate_since = now;
    m->rate_published = published;
  } else if (!m->has_state) {
    m->rate_since = now;
    m->rate_published = published;
  }
  // A transition (a command changed a mode, a parameter, the wiring) is published at once, so
  // `oscar ps` right after `oscar config` shows it, not the state of up to a second before.
  const bool transition = m->has_state && s.last_transition() != m->state.last_transition();
  m->state = s;
  m->has_state = true;
  m->pid = s.pid();
  if (m->status == "starting") {
    started(*m, s);
  } else if (transition) {
    publish();
  }
}

void Registry::started(Tracked& m, const ModuleState& now) {
  m.status = "running";
  m.running_since = Clock::now();
  m.suspended = now.suspended();  // an adopted module may have been suspended before the crash
  spdlog::info("registry: module '{}' running (incarnation {}, pid {})", m.spec->spec.name,
               m.incarnation, now.pid());
  for (auto& other : modules_) {
    if (other->replaced_by == m.spec->spec.name) {
      rewire_consumers(*other, m);
      other->status = "replaced";
    }
  }
  resume_if_whole();
  say_whom_the_system_runs_without();
  publish();
}

// Ends the module's current incarnation (killing its process unless it is gone), keeps its
// configuration for the next one and suspends the others.
void Registry::take_down(Tracked& m, bool process_gone) {
  const auto& mon = monitors_[m.spec->spec.host];
  // A module whose monitor has been replaced died with its monitor.
  m.process_gone = process_gone || (mon.pid != m.launched_by && mon.alive);
  // What the next incarnation gets back.
  if (m.has_state) m.restore = m.restore_of_state.of(m.state);
  publish();  // what happened is known now; suspending the others comes next
  if (!m.process_gone && mon.alive) {
    io_->send(LAUNCH_KILL, m.spec->spec.host, mon.pid, m.spec->spec.name, m.incarnation);
  }
  if (!left_behind(m)) suspend_all();
}

void Registry::fail(Tracked& m, const std::string& reason, bool process_gone) {
  const auto& name = m.spec->spec.name;
  const auto failed_at = Clock::now();  // the backoff runs while the others are suspended
  m.status = "failed";
  m.last_failure = reason;
  spdlog::error("registry: module '{}' failed: {}", name, reason);
  take_down(m, process_gone);
  // On a lost host the system goes on without (on_lost: continue): it waits for nobody.
  const bool go_on = left_behind(m);
  const auto hold = [&](const std::string& why) {
    if (!go_on) return set_system("suspended", why);
    spdlog::warn("registry: {}; the rest runs on (host '{}' lost, on_lost: continue)", why,
                 m.spec->spec.host);
    say_whom_the_system_runs_without();
  };
  const auto& policy = m.spec->restart;
  switch (policy.kind) {
    case RestartPolicy::Kind::kAuto:
      if (m.budget.allows(failed_at, policy.max, policy.window)) {
        m.status = "restarting";
        m.restart_at = failed_at + policy.backoff;
        hold(fmt::format("'{}' {}; restart {} of {} within {} in {}", name, reason,
                         m.budget.within(failed_at, policy.window) + 1, policy.max,
                         format_duration(policy.window), format_duration(policy.backoff)));
      } else {
        m.last_failure =
            fmt::format("{} (restart limit {} reached within {}; the module is given up)", reason,
                        policy.max, format_duration(policy.window));
        spdlog::error("registry: module '{}' reached its restart limit ({} within {}); {}", name,
                      policy.max, format_duration(policy.window),
                      policy.continue_on_limit ? "the rest continues without it"
                                               : "the system stays suspended");
        if (policy.continue_on_limit) {
          resume_if_whole();
        } else {
          hold(fmt::format("'{}' failed: {}", name, m.last_failure));
        }
      }
      break;
    case RestartPolicy::Kind::kManual:
      hold(fmt::format("'{}' {}; waiting for `oscar restart {}`", name, reason, name));
      break;
    case RestartPolicy::Kind::kReplace: {
      auto* r = find(policy.replacement);
      m.replaced_by = policy.replacement;
      set_system("suspended",
                 fmt::format("'{}' {}; replacing it with '{}'", name, reason, policy.replacement));
      if (r->status == "standby") {
        r->status = "restarting";
        r->restart_at = Clock::now();
      }
      break;
    }
  }
  publish();
}

void Registry::on_request(const RegistryRequest& r, const std::vector<std::string>& writer) {
  std::vector<std::string> origin;  // the modules of this system (not a test's own) among them
  for (const auto& m : writer) {
    if (find(m) && std::find(origin.begin(), origin.end(), m) == origin.end()) origin.push_back(m);
  }
  std::string error;
  if (r.sender().size() > kMaxRequestNameChars || r.module_name().size() > kMaxRequestNameChars) {
    // Refused before anything quotes them: a request is a sample anyone on the domain may write.
    error = fmt::format(
        "refused: a request's sender ({} bytes) and module name ({} bytes) may "
        "have at most {} characters",
        r.sender().size(), r.module_name().size(), kMaxRequestNameChars);
    spdlog::warn("registry: {}", error);
  } else if (r.kind() != REG_RESTART && r.kind() != REG_SHUTDOWN) {
    error = fmt::format(
        "refused: request kind {} is neither restart ({}) nor shutdown ({}), as "
        "in idl/oscar/registry.idl",
        static_cast<long long>(r.kind()), static_cast<int>(REG_RESTART),
        static_cast<int>(REG_SHUTDOWN));
    spdlog::warn("registry: {} (from '{}')", error, r.sender());
  } else if (!origin.empty()) {
    // Without DDS Security the sender's name is a claim; the writer's process is not.
    error = fmt::format(
        "refused: '{}' may not {}: the request comes from the process of module '{}', and only "
        "boot and operator tools (processes hosting no module of the system) may restart modules "
        "or shut the system down",
        r.sender(),
        r.kind() == REG_SHUTDOWN ? "shut the system down" : "restart '" + r.module_name() + "'",
        fmt::join(origin, "', '"));
    spdlog::warn("registry: {}", error);
  } else if (r.kind() == REG_SHUTDOWN) {
    shutting_down_ = true;
  } else if (auto* m = find(r.module_name()); !m) {
    std::vector<std::string> names;
    for (const auto& t : modules_) names.push_back(t->spec->spec.name);
    error = fmt::format("no module '{}' in system '{}' (modules: {})", r.module_name(),
                        system_.name, fmt::join(names, ", "));
  } else if (m->status == "running" || m->status == "failed") {
    // Not a failure: it neither counts against the restart limit nor becomes the last failure.
    spdlog::info("registry: restart of '{}' requested by {}", r.module_name(), r.sender());
    const bool was_running = m->status == "running";
    m->status = "restarting";
    m->restart_at = Clock::now();
    m->restart_requested = true;
    if (was_running) {
      take_down(*m, false);
      set_system("suspended",
                 fmt::format("restarting '{}' (requested by {})", r.module_name(), r.sender()));
    }
  } else {
    error = fmt::format("module '{}' is {}; only a running or failed module can be restarted",
                        r.module_name(), m->status);
  }
  io_->reply(r.id(), error);
}

}  // namespace oscar
