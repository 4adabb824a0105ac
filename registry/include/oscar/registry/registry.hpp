#pragma once
/// @file Registry: holds the system graph and keeps the system running (docs/boot.md, seed 004
/// §2.4). Launches every module through its host's monitor, learns of failures three ways
/// (process events from monitors, lapsed module heartbeats, lost monitors), suspends the
/// system, restarts/replaces per policy, re-applies configuration and wiring, and resumes.
/// Started again after a crash (`--recover`), it adopts the modules that still run and starts
/// only the others (docs/boot.md, "When the registry dies").

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <oscar/monitor_report.h>
#include <oscar/registry.h>

#include "oscar/config_client.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/shared_memory.hpp"

namespace oscar {

/// What Registry::run() throws when it finds another system's processes on its domain before it
/// started any module; oscar-registry then exits with kDomainInUseExit, which boot reports.
struct DomainInUse : std::runtime_error {
  using std::runtime_error::runtime_error;
};
inline constexpr int kDomainInUseExit = 3;
/// What oscar-registry exits with when it ends leaving the system running, for a registry after
/// it to take over (boot starts one with --recover): see Registry::run().
inline constexpr int kHandOverExit = 4;

class Registry {
 public:
  /// Joins the system's domain on `participant`; acquires no processes until run().
  /// `journal_file` (none if empty): where it keeps what a registry after it would need
  /// (configurations to restore, restart counters, restarts in progress).
  /// `recovering`: a registry before this one died; the modules its monitors report running
  /// are adopted, a host's modules are started only once its monitor has reported, and what
  /// the journal says is taken over (a journal that cannot be read is said and skipped).
  Registry(const SystemSpec& system, DdsParticipant& participant, std::string journal_file = {},
           bool recovering = false);
  ~Registry();
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;

  /// Boots the system and keeps it running until a shutdown request (or stop()); then stops the
  /// modules in reverse order, tells the monitors to exit and returns true. Returns false,
  /// leaving the system running for a registry after it, once its shared-memory port file has
  /// been removed or replaced by another process (PortFileWatch): a process that starts from
  /// then on (a restarted module, a tool) would send it nothing it hears.
  /// @throws DomainInUse if another system's processes show on the domain before the first
  ///         module would start (see other_systems_on_domain()).
  bool run();
  /// Asks run() to shut the system down and return (thread-safe).
  void stop();

 private:
  using Clock = std::chrono::steady_clock;
  struct Tracked;
  struct Monitor {
    long pid = 0;
    bool alive = false;
    std::string log_dir;
  };
  class Io;

  // Everything below runs on the run() thread; DDS callbacks only post().
  void post(std::function<void()> event);
  void on_monitor_beat(const MonitorBeat& beat);
  void on_monitor_lost(const std::string& host, long pid);
  void on_monitor_report(const MonitorReport& report);
  void on_process_event(const ProcessEvent& event);
  void on_module_state(const ModuleState& state);
  void on_module_lost(const std::string& module, unsigned incarnation);
  /// `writer`: the modules living in the process that wrote the request. Only a process hosting
  /// none of this system's (boot, an operator's tool) may restart modules and shut it down.
  void on_request(const RegistryRequest& request, const std::vector<std::string>& writer);
  void tick();
  /// Until the first module starts at boot: false while the registry's participant is younger
  /// than kDiscoveryWindow; then true, or DomainInUse if another system shows on the domain.
  bool domain_free(Clock::time_point now) const;
  /// Runs the queued events, each without holding `lock` (on mutex_).
  void run_events(std::unique_lock<std::mutex>& lock);

  void fail(Tracked& m, const std::string& reason, bool process_gone);
  void take_down(Tracked& m, bool process_gone);
  void launch(Tracked& m, unsigned incarnation);
  void started(Tracked& m, const ModuleState& state);
  /// Takes over a process a monitor runs (recovery): as if launched, waiting for its state.
  void adopt(Tracked& m, const MonitorChild& child, long monitor_pid);
  /// While recovering: whether modules of `host` may be started (its monitor has reported).
  bool may_start_on(const std::string& host) const;
  void rewire_consumers(const Tracked& failed, const Tracked& replacement);
  void suspend_all();
  /// Whether `m` is on a lost host whose system file says `on_lost: continue`: the rest does not
  /// wait for it (it is restarted when the host is back).
  bool left_behind(const Tracked& m) const;
  /// Whether `m` is not running but still counts: starting, restarting, or failed and not given
  /// up under `continue_on_limit`.
  static bool on_its_way_back(const Tracked& m);
  /// The lost hosts the system runs on without (on_lost: continue): those of the modules left
  /// behind that are on their way back.
  std::vector<std::string> hosts_run_on_without() const;
  /// While running: the message names the lost hosts the system runs on without, and says so
  /// once their modules run again.
  void say_whom_the_system_runs_without();
  void resume_if_whole();
  void recovered();
  bool configure(const std::string& module, CommandKind kind, std::vector<std::string> args);
  std::vector<bool> configure_all(const std::vector<Tracked*>& targets, CommandKind kind);
  void shutdown();
  void set_system(const std::string& state, const std::string& message);
  void publish();
  /// Takes over the restart counters, configurations and restarts in progress of the journal.
  void read_journal();
  /// Replaces the journal if what it would say changed (publish() calls it).
  void write_journal();
  Tracked* find(const std::string& name);

  const SystemSpec& system_;
  DdsParticipant& participant_;
  ConfigClient config_;
  std::vector<std::unique_ptr<Tracked>> modules_;  // in system file order
  std::map<std::string, Monitor> monitors_;        // by host
  std::string state_ = "booting";
  std::string message_;
  bool running_without_ = false;  // the message names lost hosts (say_whom_the_system_runs_without)
  bool recovering_ = false;       // until every module is back after a crash
  Clock::time_point recovery_since_{};        // when this registry started (recovering or not)
  std::map<std::string, long> reported_;      // by host: the monitor pid whose report came
  std::map<std::string, ModuleState> early_;  // recovering: states that came before adoption
  std::string journal_file_;
  long long wall_at_start_ns_ = 0;  // the wall clock at recovery_since_: the journal's times
  int adopted_ = 0;                 // modules found running when recovering
  int started_in_recovery_ = 0;     // modules no monitor ran when recovering
  bool shutting_down_ = false;
  bool launched_any_ = false;
  PortFileWatch port_file_watch_;  // looked at once a second by run()
  Clock::time_point last_publish_{};

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> events_;
  bool stop_requested_ = false;
  std::unique_ptr<Io> io_;  // last: its callbacks post() into the members above
};

}  // namespace oscar
