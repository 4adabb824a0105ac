// The registry's actions (internal): starting modules, suspending and resuming the system,
// configuration commands, the orderly shutdown and the published system state.
#include <algorithm>
#include <future>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "oscar/registry/launch_command.hpp"
#include "oscar/registry/registry.hpp"
#include "oscar/registry/running_systems.hpp"
#include "oscar/time.hpp"
#include "registry_io.hpp"
#include "registry_tracked.hpp"
#include "restore_text.hpp"

namespace oscar {
namespace {
constexpr std::chrono::milliseconds kFirstBeatGrace{3000};
// At boot, modules of one host start at most this many at a time. A starting process loads its
// plugins and discovers every other participant; a hundred of them at once on two cores starved
// the running ones' heartbeats past their lease (300 ms), and each failure suspended the system
// and made it busier still (tests/integration/scale_test.cpp).
constexpr int kStartingPerHost = 8;
}  // namespace

void Registry::launch(Tracked& m, unsigned incarnation) {
  const auto& host = m.spec->spec.host;
  const auto& mon = monitors_[host];
  launched_any_ = true;
  m.incarnation = incarnation;
  m.launched_by = mon.pid;
  m.suspended = false;
  m.status = "starting";
  m.process_gone = false;
  m.has_state = false;
  m.held = false;
  io_->send(LAUNCH_START, host, mon.pid, m.spec->spec.name, incarnation, m.restore);
  spdlog::info("registry: starting '{}' on '{}' (incarnation {})", m.spec->spec.name, host,
               incarnation);
}

// Launches what is due: at boot every module whose monitor is up, producers before their
// consumers, later the restarts whose backoff has passed (once the failed process is gone and
// its host's monitor answers).
bool Registry::domain_free(Clock::time_point now) const {
  if (launched_any_ || recovering_) return true;
  if (now - recovery_since_ < kDiscoveryWindow) return false;
  if (!other_systems_on_domain(participant_).empty()) {
    throw DomainInUse(domain_in_use(system_.domain, other_systems_in_full(participant_)));
  }
  return true;
}

void Registry::tick() {
  const auto now = Clock::now();
  // Boot looked for another system before it started the registry; on a loaded machine that
  // system's processes may answer later, so the registry looks on until it starts the first.
  if (!domain_free(now)) return;
  std::map<std::string, int> starting;  // per host
  for (const auto& m : modules_) {
    if (m->status == "starting") ++starting[m->spec->spec.host];
  }
  for (auto& m : modules_) {
    const auto& mon = monitors_[m->spec->spec.host];
    if (!mon.alive) continue;
    if (m->status == "waiting") {
      if (starting[m->spec->spec.host] >= kStartingPerHost || !may_start_on(m->spec->spec.host) ||
          std::any_of(m->launched_after.begin(), m->launched_after.end(),
                      [](const Tracked* p) { return p->status == "waiting"; })) {
        continue;
      }
      ++starting[m->spec->spec.host];
      if (state_ == "recovering") ++started_in_recovery_;
      // 1 at boot; when recovering, one more than the last incarnation its monitor reported.
      launch(*m, m->incarnation + 1);
      publish();
    } else if (m->status == "restarting" && m->process_gone && now >= m->restart_at &&
               may_start_on(m->spec->spec.host)) {
      if (m->incarnation > 0 && !m->restart_requested) {
        ++m->restarts;
        m->budget.record(now);
      }
      m->restart_requested = false;
      if (state_ == "recovering") ++started_in_recovery_;
      launch(*m, m->incarnation + 1);
      publish();
    }
  }
  // The registry keeps its own clock on the heartbeats as well: DDS reports a lapsed lease only
  // for a writer it has seen alive, and Fast DDS 2.9's liveliness timer now and then misses a
  // lapse (a hung module was caught only after 2 leases). A module's first heartbeat may come
  // late although it runs (it announced itself): discovery of a fresh process's heartbeat
  // writer took up to 2 s here, so the first one gets that long.
  for (auto& m : modules_) {
    if (m->status != "running") continue;
    const auto beat = io_->last_beat(m->spec->spec.name, m->incarnation);
    const std::chrono::milliseconds allowed =
        beat == Clock::time_point{} ? std::max(system_.lease * 2, kFirstBeatGrace) : system_.lease;
    if (now - std::max(m->running_since, beat) > allowed) {
      on_module_lost(m->spec->spec.name, m->incarnation);
    } else if (m->held && beat != Clock::time_point{}) {
      m->held = false;
      spdlog::info("registry: module '{}' sends its heartbeat again", m->spec->spec.name);
    }
  }
  if (recovering_ && std::all_of(modules_.begin(), modules_.end(), [&](const auto& m) {
        return m->status != "waiting" && may_start_on(m->spec->spec.host);
      })) {
    recovering_ = false;  // every host reported; every module was adopted or started
  }
  if (state_ == "booting" || state_ == "recovering") {
    std::vector<std::string> missing;
    for (const auto& m : modules_) {
      // Recovering, a module the registry before gave up or replaced stays so.
      const bool settled =
          m->status == "running" || m->status == "standby" ||
          (state_ == "recovering" && (m->status == "failed" || m->status == "replaced"));
      if (!settled) missing.push_back(m->spec->spec.name);
    }
    if (missing.empty() && state_ == "recovering") {
      recovered();
    } else if (missing.empty()) {
      set_system("running", "all modules announced");
    } else if (message_ != "waiting for: " + fmt::format("{}", fmt::join(missing, ", "))) {
      message_ = fmt::format("waiting for: {}", fmt::join(missing, ", "));
      publish();
    }
  }
  if (now - last_publish_ > std::chrono::seconds(1)) publish();
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

bool Registry::left_behind(const Tracked& m) const {
  const auto& host = m.spec->spec.host;
  const auto mon = monitors_.find(host);
  if (mon == monitors_.end() || mon->second.alive || mon->second.pid == 0) return false;
  for (const auto& h : system_.hosts) {
    if (h.name == host) return h.continue_when_lost;
  }
  return false;
}

bool Registry::on_its_way_back(const Tracked& m) {
  if (m.status != "starting" && m.status != "restarting" && m.status != "failed") return false;
  const bool given_up = m.status == "failed" &&
                        m.spec->restart.kind == RestartPolicy::Kind::kAuto &&
                        m.spec->restart.continue_on_limit;
  return !given_up;
}

std::vector<std::string> Registry::hosts_run_on_without() const {
  std::vector<std::string> hosts;
  for (const auto& m : modules_) {
    const auto& host = m->spec->spec.host;
    if (on_its_way_back(*m) && left_behind(*m) &&
        std::find(hosts.begin(), hosts.end(), host) == hosts.end()) {
      hosts.push_back(host);
    }
  }
  return hosts;
}

namespace {
std::string without_message(const char* verb, const std::vector<std::string>& hosts) {
  return fmt::format("{} without the modules of lost host '{}' (on_lost: continue)", verb,
                     fmt::join(hosts, "', '"));
}
}  // namespace

// Whichever lapses first, a lost host's monitor or its modules' heartbeats, a running system
// says that it runs on without them (and no longer "all modules announced").
void Registry::say_whom_the_system_runs_without() {
  if (state_ != "running") return;
  const auto without = hosts_run_on_without();
  if (!without.empty()) {
    if (const auto message = without_message("running", without); message != message_) {
      set_system("running", message);
    }
  } else if (running_without_) {
    set_system("running", "all modules running again");
  }
  running_without_ = !without.empty();
}

// Resumes once no module is on its way back; a module given up (or replaced) no longer counts,
// nor one left behind on a lost host that the system goes on without.
void Registry::resume_if_whole() {
  if (state_ != "suspended") return;
  for (const auto& m : modules_) {
    if (on_its_way_back(*m) && !left_behind(*m)) return;
  }
  // A restarted module starts running (configured by --restore): only the others wait.
  std::vector<Tracked*> targets;
  for (auto& m : modules_) {
    if (m->status == "running" && m->suspended) targets.push_back(m.get());
  }
  const auto ok = configure_all(targets, CMD_RESUME);
  for (std::size_t i = 0; i < targets.size(); ++i) targets[i]->suspended = !ok[i];
  const auto without = hosts_run_on_without();
  set_system("running",
             without.empty() ? std::string("resumed") : without_message("resumed", without));
  running_without_ = !without.empty();
}

bool Registry::configure(const std::string& module, CommandKind kind,
                         std::vector<std::string> args) {
  const auto start = Clock::now();
  try {
    const auto reply = config_.send(module, kind, std::move(args), std::chrono::milliseconds(2000));
    if (!reply.ok()) spdlog::warn("registry: {}: {}", module, reply.error());
    const auto took = Clock::now() - start;
    if (took > std::chrono::milliseconds(100)) {
      spdlog::warn("registry: command {} to '{}' took {:.0f} ms", static_cast<int>(kind), module,
                   std::chrono::duration<double, std::milli>(took).count());
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

void Registry::shutdown() {
  shutting_down_ = true;  // also when stop() asked: modules ending now are not failures
  set_system("stopping", "shutting down in reverse boot order");
  for (auto it = modules_.rbegin(); it != modules_.rend(); ++it) {
    auto& m = **it;
    if (m.process_gone || m.incarnation == 0) continue;
    const auto& mon = monitors_[m.spec->spec.host];
    if (mon.alive)
      io_->send(LAUNCH_STOP, m.spec->spec.host, mon.pid, m.spec->spec.name, m.incarnation);
    // In order: wait for this one to end before stopping the next.
    const auto until = Clock::now() + std::chrono::seconds(6);
    std::unique_lock lock(mutex_);
    while (!m.process_gone && mon.alive && Clock::now() < until) {
      wake_.wait_for(lock, std::chrono::milliseconds(10), [&] { return !events_.empty(); });
      run_events(lock);
    }
    m.status = "stopped";
  }
  for (const auto& [host, mon] : monitors_) {
    if (mon.alive) io_->send(LAUNCH_EXIT, host, mon.pid, "", 0);
  }
  // The registry exits next: without this its monitors' exit requests were sometimes lost, and
  // a monitor over ssh stayed until boot closed its connection.
  io_->wait_until_delivered(std::chrono::seconds(1));
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
    e.debug(m->spec->debug.describe());
    if (m->has_state) e.state(m->state);
    s.modules().push_back(std::move(e));
  }
  // The journal first: what anyone saw published, a registry after this one knows.
  write_journal();
  io_->publish(s);
  last_publish_ = Clock::now();
}

}  // namespace oscar
