// The registry's recovery after a crash (docs/boot.md, "When the registry dies"): adopting what
// the monitors report, the journal it keeps for a registry after it, and reading it back.
#include <algorithm>
#include <optional>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "oscar/registry/registry.hpp"
#include "oscar/time.hpp"
#include "registry_io.hpp"
#include "registry_journal.hpp"
#include "registry_tracked.hpp"

namespace oscar {

// A monitor's report of its module processes. While recovering, the modules it runs are
// adopted; a host's other modules are started only after its report (may_start_on), so none
// runs twice.
void Registry::on_monitor_report(const MonitorReport& r) {
  const bool first = reported_[r.host()] != r.monitor_pid();
  reported_[r.host()] = r.monitor_pid();
  if (!recovering_) return;
  if (first) {
    spdlog::info("registry: monitor of host '{}' (pid {}) runs {} module processes", r.host(),
                 r.monitor_pid(), r.children().size());
  }
  for (const auto& child : r.children()) {
    auto* m = find(child.module_name());
    if (!m || m->spec->spec.host != r.host()) continue;
    if (m->status == "waiting" || m->status == "standby") {  // standby: it had taken over
      adopt(*m, child, r.monitor_pid());
    } else if (m->status == "restarting" && child.incarnation() > m->incarnation) {
      // The registry before had started the restart the journal says is due: it counts.
      if (!m->restart_requested) {
        ++m->restarts;
        m->budget.record(Clock::now());
      }
      m->restart_requested = false;
      adopt(*m, child, r.monitor_pid());
    } else if ((m->status == "restarting" || m->status == "failed" || m->status == "replaced") &&
               child.incarnation() == m->incarnation && m->process_gone) {
      // The failed process still runs (a hung module the registry before had not killed yet).
      m->process_gone = false;
      m->launched_by = r.monitor_pid();
      io_->send(LAUNCH_KILL, r.host(), r.monitor_pid(), m->spec->spec.name, m->incarnation);
    }
  }
}

void Registry::adopt(Tracked& m, const MonitorChild& child, long monitor_pid) {
  const auto& name = m.spec->spec.name;
  m.incarnation = child.incarnation();
  m.pid = child.pid();
  m.launched_by = monitor_pid;
  m.status = "starting";  // until its state comes: then it runs (started())
  m.process_gone = false;
  m.has_state = false;
  m.held = false;
  ++adopted_;
  spdlog::info("registry: adopting '{}' on '{}' (incarnation {}, pid {})", name, m.spec->spec.host,
               m.incarnation, m.pid);
  if (const auto it = early_.find(name); it != early_.end()) {
    const auto state = it->second;
    early_.erase(it);
    if (state.incarnation() == m.incarnation) on_module_state(state);
  }
  publish();
}

bool Registry::may_start_on(const std::string& host) const {
  if (!recovering_) return true;
  // One lease as well: the replay of the monitor's process events (the incarnations its modules
  // had) comes on a writer of its own, matched in its own time.
  const auto reported = reported_.find(host);
  const auto monitor = monitors_.find(host);
  return reported != reported_.end() && monitor != monitors_.end() &&
         reported->second == monitor->second.pid && Clock::now() - recovery_since_ >= system_.lease;
}

// Every module runs again after a crash of the registry: those the registry before suspended
// (it died during a restart) are resumed.
void Registry::recovered() {
  const auto summary =
      fmt::format("registry recovered: {} modules running were adopted, {} started", adopted_,
                  started_in_recovery_);
  for (const auto& m : modules_) {
    const bool given_up =
        m->spec->restart.kind == RestartPolicy::Kind::kAuto && m->spec->restart.continue_on_limit;
    if (m->status == "failed" && !given_up) {
      // As the registry before had left it: suspended until the operator restarts the module.
      set_system("suspended",
                 fmt::format("{}; '{}' failed: {}", summary, m->spec->spec.name, m->last_failure));
      return;
    }
  }
  std::vector<Tracked*> targets;
  for (auto& m : modules_) {
    if (m->status == "running" && m->suspended) targets.push_back(m.get());
  }
  const auto ok = configure_all(targets, CMD_RESUME);
  for (std::size_t i = 0; i < targets.size(); ++i) targets[i]->suspended = !ok[i];
  set_system("running", summary);
}

void Registry::write_journal() {
  if (journal_file_.empty()) return;
  // One fixed mapping from the steady clock: the same instant is written the same each time.
  const auto to_wall = [&](Clock::time_point t) {
    return wall_at_start_ns_ +
           std::chrono::duration_cast<std::chrono::nanoseconds>(t - recovery_since_).count();
  };
  internal::RegistryJournal journal;
  bool changed = false;
  for (const auto& m : modules_) {
    internal::JournalModule j;
    j.name = m->spec->spec.name;
    j.incarnation = m->incarnation;
    // A running module's own state is what it would get back if it failed now.
    j.restore =
        m->status == "running" && m->has_state ? m->restore_of_state.of(m->state) : m->restore;
    j.restarts = m->restarts;
    for (const auto t : m->budget.restarts()) j.counted.push_back(to_wall(t));
    j.last_failure = m->last_failure;
    j.status = m->status;
    j.replaced_by = m->replaced_by;
    j.restart_requested = m->restart_requested;
    j.restart_at = m->status == "restarting" ? to_wall(m->restart_at) : 0;
    changed = changed || j != m->journaled;
    journal.modules.push_back(std::move(j));
  }
  // Written when it says something new, not for each state published: compared field by field,
  // not as YAML text (making the text for every module on each publish cost the registry the
  // square of the modules while a system booted, docs/benchmarks.md).
  if (!changed) return;
  for (std::size_t i = 0; i < modules_.size(); ++i) modules_[i]->journaled = journal.modules[i];
  journal.written = wall_now();
  try {
    journal.write(journal_file_);
  } catch (const std::exception& e) {
    spdlog::error("registry: {} (a registry after this one will not know it)", e.what());
  }
}

void Registry::read_journal() {
  if (journal_file_.empty()) return;
  std::optional<internal::RegistryJournal> journal;
  try {
    journal = internal::RegistryJournal::read(journal_file_);
  } catch (const std::exception& e) {
    spdlog::error(
        "registry: {}; recovering without it: restart counters start again from 0, and a module "
        "that is not running starts with its configuration from the system file",
        e.what());
    return;
  }
  if (!journal) {
    spdlog::warn("registry: no journal {}; recovering from what the modules and monitors say",
                 journal_file_);
    return;
  }
  const auto now = Clock::now();
  const auto wall = wall_now();
  const auto to_steady = [&](Stamp t) { return now - std::chrono::nanoseconds(wall - t); };
  for (const auto& j : journal->modules) {
    auto* m = find(j.name);
    if (!m) continue;  // the system file changed: nothing to take over
    m->incarnation = j.incarnation;
    m->restore = j.restore;
    m->restarts = j.restarts;
    for (const auto t : j.counted) m->budget.record(to_steady(t));
    m->last_failure = j.last_failure;
    m->replaced_by = j.replaced_by;
    if (j.status == "failed" || j.status == "replaced") {
      // Given up, waiting for the operator, or replaced: it stays so (its process is gone, or
      // is killed once its monitor reports it: on_monitor_report).
      m->status = j.status;
      m->process_gone = true;
    } else if (j.status == "restarting") {
      m->status = "restarting";
      m->restart_at = to_steady(j.restart_at);
      m->restart_requested = j.restart_requested;
      m->process_gone = true;  // unless its monitor says otherwise (on_monitor_report)
      spdlog::info("registry: the journal says '{}' (incarnation {}) is due to restart", j.name,
                   j.incarnation);
    }
  }
  spdlog::info("registry: journal {} of {} modules read", journal_file_, journal->modules.size());
}

}  // namespace oscar
