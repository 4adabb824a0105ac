#include "oscar/registry/registry.hpp"

#include <algorithm>
#include <future>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "oscar/registry/launch_command.hpp"
#include "oscar/time.hpp"
#include "registry_io.hpp"
#include "registry_tracked.hpp"

namespace oscar {

Registry::Registry(const SystemSpec& system, DdsParticipant& participant)
    : system_(system), participant_(participant), config_(participant, "registry") {
  for (const auto& m : system_.modules) {
    auto t = std::make_unique<Tracked>();
    t->spec = &m;
    t->status = m.standby ? "standby" : "waiting";
    modules_.push_back(std::move(t));
  }
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

void Registry::run() {
  spdlog::info("registry: system '{}' with {} modules on {} hosts, domain {}", system_.name,
               modules_.size(), system_.hosts.size(), system_.domain);
  publish();
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait_for(lock, std::chrono::milliseconds(10),
                   [&] { return stop_requested_ || !events_.empty(); });
    if (stop_requested_) break;
    while (!events_.empty()) {
      auto event = std::move(events_.front());
      events_.pop_front();
      lock.unlock();
      event();
      lock.lock();
    }
    if (shutting_down_) break;
    lock.unlock();
    tick();
    lock.lock();
  }
  lock.unlock();
  shutdown();
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
    if (m->spec->spec.host != beat.host() || m->process_gone || m->incarnation == 0 ||
        m->status == "running" || m->status == "starting") {
      continue;
    }
    if (m->launched_by == beat.pid()) {
      // The monitor was only slow: a failed module of it may still run. Kill it; the restart
      // follows its reported exit.
      io_->send(LAUNCH_KILL, beat.host(), beat.pid(), m->spec->spec.name, m->incarnation, {}, {});
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
  publish();
}

void Registry::on_process_event(const ProcessEvent& e) {
  auto* m = find(e.module_name());
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
  std::string reason = e.kind() == PROC_START_FAILED ? "could not start: " + e.detail()
                       : e.signal() != 0 ? fmt::format("killed by signal {}", e.signal())
                                         : fmt::format("exited with code {}", e.exit_code());
  if (e.kind() == PROC_EXITED && !e.detail().empty()) {
    const auto last = e.detail().substr(e.detail().rfind('\n') + 1);
    if (!last.empty()) reason += " (last output: " + last + ")";
  }
  fail(*m, reason, true);
}

void Registry::on_module_lost(const std::string& module, unsigned incarnation) {
  auto* m = find(module);
  if (!m || shutting_down_ || incarnation != m->incarnation || m->status != "running") return;
  const auto reason =
      fmt::format("heartbeat lost for {} (hung or stopped)", format_duration(system_.lease));
  const auto& host = m->spec->spec.host;
  fail(*m, monitors_[host].alive ? reason : fmt::format("host '{}' lost ({})", host, reason),
       false);
}

void Registry::on_module_state(const ModuleState& s) {
  auto* m = find(s.module_name());
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
  m->state = s;
  m->has_state = true;
  m->pid = s.pid();
  if (m->status == "starting") started(*m, s);
}

void Registry::started(Tracked& m, const ModuleState& now) {
  m.status = "running";
  m.running_since = Clock::now();
  spdlog::info("registry: module '{}' running (incarnation {}, pid {})", m.spec->spec.name,
               m.incarnation, now.pid());
  for (auto& other : modules_) {
    if (other->replaced_by == m.spec->spec.name) {
      rewire_consumers(*other, m);
      other->status = "replaced";
    }
  }
  resume_if_whole();
  publish();
}

void Registry::fail(Tracked& m, const std::string& reason, bool process_gone) {
  const auto& name = m.spec->spec.name;
  const auto& mon = monitors_[m.spec->spec.host];
  m.status = "failed";
  m.last_failure = reason;
  // A module whose monitor has been replaced died with its monitor.
  m.process_gone = process_gone || (mon.pid != m.launched_by && mon.alive);
  if (m.has_state) m.config = m.state;  // what the next incarnation gets back
  spdlog::error("registry: module '{}' failed: {}", name, reason);
  publish();  // the failure is known now; suspending the others comes next
  if (!m.process_gone && mon.alive) {
    io_->send(LAUNCH_KILL, m.spec->spec.host, mon.pid, name, m.incarnation, {}, {});
  }
  suspend_all();
  const auto& policy = m.spec->restart;
  switch (policy.kind) {
    case RestartPolicy::Kind::kAuto:
      if (static_cast<int>(m.restarts) < policy.max) {
        m.status = "restarting";
        m.restart_at = Clock::now() + policy.backoff;
        set_system("suspended",
                   fmt::format("'{}' {}; restart {} of {} in {}", name, reason, m.restarts + 1,
                               policy.max, format_duration(policy.backoff)));
      } else {
        m.last_failure = fmt::format("{} (restart limit {} reached; the module is given up)",
                                     reason, policy.max);
        spdlog::error("registry: module '{}' reached its restart limit ({}); {}", name, policy.max,
                      policy.continue_on_limit ? "the rest continues without it"
                                               : "the system stays suspended");
        if (policy.continue_on_limit) {
          resume_if_whole();
        } else {
          set_system("suspended", fmt::format("'{}' failed: {}", name, m.last_failure));
        }
      }
      break;
    case RestartPolicy::Kind::kManual:
      set_system("suspended",
                 fmt::format("'{}' {}; waiting for `oscar restart {}`", name, reason, name));
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

void Registry::launch(Tracked& m, unsigned incarnation) {
  const auto& host = m.spec->spec.host;
  const auto& mon = monitors_[host];
  m.incarnation = incarnation;
  m.launched_by = mon.pid;
  m.suspended = false;
  m.status = "starting";
  m.process_gone = false;
  m.has_state = false;
  auto argv = module_command(system_, *m.spec, incarnation, "oscar-run", mon.log_dir);
  if (m.config) argv.insert(argv.end(), {"--restore", restore_text(*m.config)});
  io_->send(LAUNCH_START, host, mon.pid, m.spec->spec.name, incarnation, argv,
            {"OSCAR_RUN_DIR=" + mon.log_dir});
  spdlog::info("registry: starting '{}' on '{}' (incarnation {})", m.spec->spec.name, host,
               incarnation);
}

// Launches what is due: at boot every module whose monitor is up, later the restarts whose
// backoff has passed (once the failed process is gone and its host's monitor answers).
void Registry::tick() {
  const auto now = Clock::now();
  for (auto& m : modules_) {
    const auto& mon = monitors_[m->spec->spec.host];
    if (!mon.alive) continue;
    if (m->status == "waiting") {
      launch(*m, 1);
      publish();
    } else if (m->status == "restarting" && m->process_gone && now >= m->restart_at) {
      if (m->incarnation > 0) ++m->restarts;
      launch(*m, m->incarnation + 1);
      publish();
    }
  }
  // DDS reports a lapsed lease only for a writer it has seen alive; a module that hangs before
  // its first heartbeat arrives is caught here, by the age of its last heartbeat.
  for (auto& m : modules_) {
    if (m->status != "running") continue;
    const auto last =
        std::max(m->running_since, io_->last_beat(m->spec->spec.name, m->incarnation));
    if (now - last > system_.lease * 2) on_module_lost(m->spec->spec.name, m->incarnation);
  }
  if (state_ == "booting") {
    std::vector<std::string> missing;
    for (const auto& m : modules_) {
      if (m->status != "running" && m->status != "standby") missing.push_back(m->spec->spec.name);
    }
    if (missing.empty()) {
      set_system("running", "all modules announced");
    } else if (message_ != "waiting for: " + fmt::format("{}", fmt::join(missing, ", "))) {
      message_ = fmt::format("waiting for: {}", fmt::join(missing, ", "));
      publish();
    }
  }
  if (now - last_publish_ > std::chrono::seconds(1)) publish();
}

// What the coordinator had made of the module (modes, stub, parameters, wiring), from its last
// announcement, as `oscar-run --restore` takes it: the new incarnation starts configured.
std::string Registry::restore_text(const ModuleState& last) {
  YAML::Emitter out;
  out << YAML::Flow << YAML::BeginMap;
  for (const auto& k : last.kernels()) {
    out << YAML::Key << k.name() << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "mode" << YAML::Value
        << (k.mode() == "continuous"    ? fmt::format("continuous:{}ns", k.cycle_ns())
            : k.mode() == "deactivated" ? std::string("deactivated")
            : k.trigger() == "default" || k.trigger().empty() ? std::string("single_step")
                                                              : "single_step:" + k.trigger());
    out << YAML::Key << "stub" << YAML::Value << k.stub();
    out << YAML::Key << "params" << YAML::Value << YAML::Load(k.params());
    out << YAML::Key << "inputs" << YAML::Value << YAML::BeginMap;
    for (const auto& wire : k.inputs()) {
      const auto eq = wire.find('=');
      out << YAML::Key << wire.substr(0, eq) << YAML::Value << wire.substr(eq + 1);
    }
    out << YAML::EndMap << YAML::EndMap;
  }
  out << YAML::EndMap;
  return out.c_str();
}

// `replacement` takes over: inputs that read kernel i of the failed module now read kernel i
// of the replacement (same channel names; boot checked the replacement is standby).
void Registry::rewire_consumers(const Tracked& failed, const Tracked& replacement) {
  const auto& from = failed.spec->spec.kernels;
  const auto& to = replacement.spec->spec.kernels;
  for (auto& c : modules_) {
    if (c->status != "running" || !c->has_state || c.get() == &replacement) continue;
    for (const auto& k : c->state.kernels()) {
      for (const auto& wire : k.inputs()) {
        const auto eq = wire.find('=');
        const auto source = wire.substr(eq + 1);
        const auto kernel = source.substr(0, source.find('/'));
        for (std::size_t i = 0; i < from.size() && i < to.size(); ++i) {
          if (from[i].name != kernel) continue;
          const auto target = to[i].name + source.substr(source.find('/'));
          spdlog::info("registry: rewiring {}.{} from {} to {}", k.name(), wire.substr(0, eq),
                       source, target);
          configure(c->spec->spec.name, CMD_REWIRE, {k.name(), wire.substr(0, eq), target});
        }
      }
    }
  }
}

// The caller publishes the new state once it has decided what happens next.
void Registry::suspend_all() {
  if (state_ == "suspended") return;
  std::vector<Tracked*> targets;
  for (auto& m : modules_) {
    if (m->status == "running" && !m->suspended) targets.push_back(m.get());
  }
  const auto ok = configure_all(targets, CMD_SUSPEND);
  for (std::size_t i = 0; i < targets.size(); ++i) targets[i]->suspended = ok[i];
  state_ = "suspended";
}

// Resumes once no module is on its way back; a module given up (or replaced) no longer counts.
void Registry::resume_if_whole() {
  if (state_ != "suspended") return;
  for (const auto& m : modules_) {
    if (m->status == "starting" || m->status == "restarting") return;
    const bool given_up = m->status == "failed" &&
                          m->spec->restart.kind == RestartPolicy::Kind::kAuto &&
                          m->spec->restart.continue_on_limit;
    if (m->status == "failed" && !given_up) return;
  }
  // A restarted module starts running (configured by --restore): only the others wait.
  std::vector<Tracked*> targets;
  for (auto& m : modules_) {
    if (m->status == "running" && m->suspended) targets.push_back(m.get());
  }
  const auto ok = configure_all(targets, CMD_RESUME);
  for (std::size_t i = 0; i < targets.size(); ++i) targets[i]->suspended = !ok[i];
  set_system("running", "resumed");
}

bool Registry::configure(const std::string& module, CommandKind kind,
                         std::vector<std::string> args) {
  const auto start = Clock::now();
  try {
    const auto reply = config_.send(module, kind, std::move(args), std::chrono::milliseconds(2000));
    if (!reply.ok()) spdlog::warn("registry: {}: {}", module, reply.error());
    const auto took = Clock::now() - start;
    if (took > std::chrono::milliseconds(100)) {
      spdlog::warn("registry: command {} to '{}' took {}", static_cast<int>(kind), module,
                   format_duration(std::chrono::duration_cast<std::chrono::nanoseconds>(took)));
    }
    return reply.ok();
  } catch (const std::exception& e) {
    spdlog::warn("registry: {}", e.what());
    return false;
  }
}

// The same command to several modules at once: the slowest reply sets the pace, not the sum.
std::vector<bool> Registry::configure_all(const std::vector<Tracked*>& targets, CommandKind kind) {
  std::vector<std::future<bool>> replies;
  for (auto* m : targets) {
    replies.push_back(std::async(
        std::launch::async, [this, m, kind] { return configure(m->spec->spec.name, kind, {}); }));
  }
  std::vector<bool> ok;
  for (auto& r : replies) ok.push_back(r.get());
  return ok;
}

void Registry::on_request(const RegistryRequest& r) {
  std::string error;
  if (r.kind() == REG_SHUTDOWN) {
    shutting_down_ = true;
  } else if (auto* m = find(r.module_name()); !m) {
    std::vector<std::string> names;
    for (const auto& t : modules_) names.push_back(t->spec->spec.name);
    error = fmt::format("no module '{}' in system '{}' (modules: {})", r.module_name(),
                        system_.name, fmt::join(names, ", "));
  } else if (m->status == "running") {
    fail(*m, "restart requested by " + r.sender(), false);
    m->restart_at = Clock::now();
    m->status = "restarting";
  } else if (m->status == "failed") {
    m->status = "restarting";
    m->restart_at = Clock::now();
    spdlog::info("registry: restart of '{}' requested by {}", r.module_name(), r.sender());
  } else {
    error = fmt::format("module '{}' is {}; only a running or failed module can be restarted",
                        r.module_name(), m->status);
  }
  io_->reply(r.id(), error);
}

void Registry::shutdown() {
  set_system("stopping", "shutting down in reverse boot order");
  for (auto it = modules_.rbegin(); it != modules_.rend(); ++it) {
    auto& m = **it;
    if (m.process_gone || m.incarnation == 0) continue;
    const auto& mon = monitors_[m.spec->spec.host];
    if (mon.alive)
      io_->send(LAUNCH_STOP, m.spec->spec.host, mon.pid, m.spec->spec.name, m.incarnation, {}, {});
    // In order: wait for this one to end before stopping the next.
    const auto until = Clock::now() + std::chrono::seconds(6);
    std::unique_lock lock(mutex_);
    while (!m.process_gone && mon.alive && Clock::now() < until) {
      wake_.wait_for(lock, std::chrono::milliseconds(10), [&] { return !events_.empty(); });
      while (!events_.empty()) {
        auto event = std::move(events_.front());
        events_.pop_front();
        lock.unlock();
        event();
        lock.lock();
      }
    }
    m.status = "stopped";
  }
  for (const auto& [host, mon] : monitors_) {
    if (mon.alive) io_->send(LAUNCH_EXIT, host, mon.pid, "", 0, {}, {});
  }
  set_system("stopped", "all modules stopped");
}

void Registry::set_system(const std::string& state, const std::string& message) {
  if (state != state_) spdlog::info("registry: system {} ({})", state, message);
  state_ = state;
  message_ = message;
  publish();
}

void Registry::publish() {
  SystemState s;
  s.system(system_.name);
  s.state(state_);
  s.message(message_);
  s.stamp_ns(static_cast<unsigned long long>(wall_now()));
  for (const auto& [host, mon] : monitors_) {
    if (!mon.alive) s.hosts_lost().push_back(host);
  }
  for (const auto& m : modules_) {
    ModuleEntry e;
    e.name(m->spec->spec.name);
    e.host(m->spec->spec.host);
    e.pid(static_cast<std::int32_t>(m->pid));
    e.incarnation(m->incarnation);
    e.status(m->status);
    e.restarts(m->restarts);
    e.last_failure(m->last_failure);
    e.cues_per_s(m->cues_per_s);
    if (m->has_state) e.state(m->state);
    s.modules().push_back(std::move(e));
  }
  io_->publish(s);
  last_publish_ = Clock::now();
}

}  // namespace oscar
