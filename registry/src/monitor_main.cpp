// oscar-monitor: one per host (docs/boot.md). Starts module processes when the registry asks,
// captures their output, reports how they end, and shows it is alive with a heartbeat.
#include <poll.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <oscar/registryPubSubTypes.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "clock_prober.hpp"
#if OSCAR_ZERO_COPY
#include "host_roudi.hpp"
#endif
#include "janitor.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/process_util.hpp"
#include "oscar/registry/host_check.hpp"
#include "oscar/registry/launch_command.hpp"
#include "oscar/registry/monitor_report_topic.hpp"
#include "oscar/registry/supervisor.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/security_files.hpp"
#include "oscar/shared_memory.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace {

using Clock = std::chrono::steady_clock;

oscar::ProcessEvent event(const std::string& host, const std::string& module, unsigned incarnation,
                          oscar::ProcessEventKind kind, long pid) {
  oscar::ProcessEvent e;
  e.host(host);
  e.module_name(module);
  e.incarnation(incarnation);
  e.kind(kind);
  e.pid(static_cast<std::int32_t>(pid));
  e.exit_code(0);
  e.signal(0);
  return e;
}

// What this monitor runs, for a registry that restarts after a crash (monitor_report.idl).
oscar::MonitorReport report(const std::string& host, long own_pid,
                            const oscar::Supervisor& supervisor) {
  oscar::MonitorReport r;
  r.host(host);
  r.monitor_pid(static_cast<std::int32_t>(own_pid));
  r.stamp_ns(static_cast<unsigned long long>(oscar::wall_now()));
  for (const auto& c : supervisor.children()) {
    oscar::MonitorChild child;
    child.module_name(c.module);
    child.incarnation(c.incarnation);
    child.pid(static_cast<std::int32_t>(c.pid));
    r.children().push_back(std::move(child));
  }
  return r;
}

bool same_children(const oscar::MonitorReport& a, const oscar::MonitorReport& b) {
  return a.children() == b.children();
}

// sshd hands the session's command pipes (or sockets) for its output; when the connection ends
// it closes their other ends, which poll() reports as a hang-up or error on stdout.
bool connection_lost() {
  pollfd out{1, 0, 0};
  return poll(&out, 1, 0) == 1 && (out.revents & (POLLHUP | POLLERR)) != 0;
}

// When a monitor has been without a registry for longer than the system's headless_limit.
// Armed only once a registry has been seen: at boot the monitor may start first. The registry is
// "seen" while its launch writer is matched; Fast DDS drops a participant that went silent
// after its discovery lease (3 s), so the limit counts from then. A registry that boot restarts
// is matched again long before (its new writer is matched before the old one is dropped).
class HeadlessWatch {
 public:
  explicit HeadlessWatch(std::optional<std::chrono::milliseconds> limit) : limit_(limit) {}
  /// True once, when the registry has been missing for the limit.
  bool over(bool registry_seen, Clock::time_point now) {
    if (registry_seen) {
      armed_ = true;
      alone_ = false;
      return false;
    }
    if (!armed_ || !limit_) return false;
    if (!alone_) {
      alone_ = true;
      alone_since_ = now;
      spdlog::warn("the registry is gone (no participant of it for the discovery lease)");
    }
    if (now - alone_since_ < *limit_) return false;
    armed_ = false;  // until a registry is seen again
    return true;
  }

 private:
  std::optional<std::chrono::milliseconds> limit_;
  bool armed_ = false;
  bool alone_ = false;
  Clock::time_point alone_since_{};
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar-monitor: starts and watches the module processes of one host"};
  std::string file, host, log_dir;
  int domain = -1;
  app.add_option("--system", file, "the system file")->required();
  app.add_option("--host", host, "this host's name in the system file")->required();
  app.add_option("-d,--domain", domain, "DDS domain (default: the file's)");
  app.add_option("--log-dir", log_dir, "where module output goes (default /tmp/oscar/...)");
  std::string check;
  app.add_option("--check", check,
                 "only check that this host can run its modules of the system file whose content "
                 "has this fingerprint (oscar boot does, over ssh), print the problems, exit");
  bool over_ssh = false;
  app.add_flag("--over-ssh", over_ssh,
               "runs as the command of an ssh session: when the connection ends, stop this "
               "host's modules in order and exit");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  if (!check.empty()) {
    std::printf("%s\n", oscar::check_banner().c_str());  // first, whatever else fails
    oscar::register_standard_cue_types();
    const auto problems = oscar::check_this_host(file, host, check, oscar::plugin_search_path(),
                                                 oscar::sibling_program);
    for (const auto& p : problems) std::printf("%s\n", p.c_str());
    return problems.empty() ? 0 : 2;
  }
  // A lost connection closes the pipes sshd gave us: a write to them must not kill the monitor
  // (SIGPIPE) before it has stopped its modules in order.
  if (over_ssh) std::signal(SIGPIPE, SIG_IGN);

  const auto signals = oscar::block_stop_signals();
  const auto pattern = "%H:%M:%S.%e %^%-5l%$ [monitor " + host + "] %v";
  spdlog::set_pattern(pattern);

  int code = 0;
  try {
    auto system = oscar::SystemSpec::load(file);
    system.host(host);  // throws for an unknown host
    if (domain >= 0) system.override_domain(domain);
    domain = system.domain;
    if (log_dir.empty()) {
      log_dir = fmt::format("/tmp/oscar/{}-{}/{}", system.name, system.domain, host);
    }
    const auto test_clock_offset = oscar::test_clock_offset_from_environment();
    oscar::Supervisor supervisor(log_dir);
    if (over_ssh) {
      // What this monitor says after the connection is gone (stopping the host's modules) would
      // be lost with it: on the host, its log goes to a file too (no module name has a '-').
      auto on_host_log =
          std::make_shared<spdlog::sinks::basic_file_sink_mt>(log_dir + "/oscar-monitor.log");
      on_host_log->set_pattern(pattern);
      spdlog::default_logger()->sinks().push_back(on_host_log);
      spdlog::flush_on(spdlog::level::info);
    }
    auto network = system.network_for(host, oscar::security_files::monitor_identity(host));
    network.shm_segment_bytes = oscar::shm_segment_bytes_for(network, false);  // reports only
    // With discovery servers, a monitor learns only of the participants it shares a topic with
    // (the registry, boot, the tools that read its reports), not of every module's endpoints
    // on every host (docs/network.md).
    oscar::DdsParticipant participant(system.domain, "oscar-monitor:" + host, network,
                                      oscar::DiscoveryScope::kSharedTopics);
    oscar::TopicWriter<oscar::ProcessEvent, oscar::ProcessEventPubSubType> events(
        participant, oscar::topics::process_events());
    oscar::TopicWriter<oscar::MonitorBeat, oscar::MonitorBeatPubSubType> beats(
        participant, oscar::topics::monitor_alive(system.lease));
    oscar::TopicWriter<oscar::MonitorReport, oscar::MonitorReportPubSubType> reports(
        participant, oscar::topics::monitor_children());

    std::mutex mutex;
    std::deque<oscar::LaunchRequest> requests;
    std::set<unsigned long long> seen;
    const long own_pid = getpid();
    oscar::TopicReader<oscar::LaunchRequest, oscar::LaunchRequestPubSubType> launches(
        participant, oscar::topics::launch(), [&](const oscar::LaunchRequest& q, const auto&) {
          if (q.host() != host || q.monitor_pid() != own_pid) return;
          std::lock_guard lock(mutex);
          if (seen.insert(q.id()).second) requests.push_back(q);
        });

    const auto report_exit = [&](const oscar::ProcessExit& x) {
      auto ev = event(host, x.module, x.incarnation, oscar::PROC_EXITED, x.pid);
      ev.exit_code(x.exit_code);
      ev.signal(x.signal);
      ev.detail(x.last_output);
      events.write(ev);
    };
    const auto stop_modules = [&] {
      for (const auto& x : supervisor.stop_all(std::chrono::milliseconds(5000))) {
        spdlog::log(x.exit_code == 0 ? spdlog::level::info : spdlog::level::warn, "{} (pid {}) {}",
                    x.module, x.pid, x.describe());
        report_exit(x);
      }
    };
    HeadlessWatch headless(system.headless_limit);
    if (test_clock_offset != std::chrono::nanoseconds::zero()) {
      spdlog::warn(
          "OSCAR_CLOCK_OFFSET_MS: this monitor's clock probes are shifted by {} ms (a "
          "test hook, for tests only)",
          std::chrono::duration_cast<std::chrono::milliseconds>(test_clock_offset).count());
    }
    // How far this host's clock is from the registry's (docs/boot.md, "Clocks").
    oscar::ClockProber clock(participant, host, own_pid, test_clock_offset);

    oscar::MonitorBeat beat;
    beat.host(host);
    beat.pid(static_cast<std::int32_t>(own_pid));
    beat.log_dir(log_dir);
    spdlog::info("watching host '{}' (domain {}), module output in {}", host, system.domain,
                 log_dir);
    std::map<std::string, Clock::time_point> stopping;  // SIGKILL if still there by then
    oscar::Janitor janitor(system.domain, network);
#if OSCAR_ZERO_COPY
    std::optional<oscar::HostRoudi> roudi;  // the host's RouDi, for zero-copy cues
    if (system.zero_copy) roudi.emplace(system.zero_copy->chunks, log_dir);
    // The first launches wait until the host's RouDi listens (at most kSettlePatience), so that
    // modules begin in shared memory instead of moving there from DDS a moment later.
    const auto patience_ends = Clock::now() + oscar::HostRoudi::kSettlePatience;
    bool patience_over = false;
    const auto await_roudi = [&] {
      if (!roudi || patience_over || roudi->settled()) return false;
      if (Clock::now() < patience_ends) return true;
      patience_over = true;
      spdlog::warn(
          "RouDi does not listen {} s after the monitor started: starting modules anyway (their "
          "plain cues go through DDS until it listens)",
          oscar::HostRoudi::kSettlePatience.count());
      return false;
    };
#else
    const auto await_roudi = [] { return false; };
    if (system.zero_copy) spdlog::error("{}", oscar::zero_copy_unavailable().value_or(""));
#endif
    // The heartbeat has a thread of its own: starting processes must not delay it.
    std::jthread beater([&](std::stop_token stop) {
      auto next = Clock::now();
      while (!stop.stop_requested()) {
        beats.write(beat);
        next += system.lease / 3;
        std::this_thread::sleep_until(next);
      }
    });
    // Written on every change and every lease/3: a registry started after a crash waits for it
    // before it starts anything on this host.
    auto last_report = report(host, own_pid, supervisor);
    auto next_report = Clock::now();
    bool exit_requested = false;
    while (!exit_requested) {
      if (oscar::wait_for_stop(signals, std::chrono::milliseconds(5))) break;
      if (over_ssh && connection_lost()) {
        spdlog::warn("the ssh connection to boot is gone: stopping this host's modules");
        break;
      }
      if (headless.over(launches.matched() > 0, Clock::now())) {
        // A network split, or a registry gone for good: nobody would restart, stop or
        // reconfigure these modules, and after the split heals the registry restarts them.
        spdlog::warn(
            "no registry for {} (headless_limit): stopping this host's modules in order; they "
            "start again when the registry asks",
            oscar::format_duration(*system.headless_limit));
        stop_modules();
        stopping.clear();
      }
      std::deque<oscar::LaunchRequest> batch;  // handled without holding the lock
      {
        std::lock_guard lock(mutex);
        if (!await_roudi()) batch.swap(requests);
      }
      for (const auto& q : batch) {
        switch (q.kind()) {
          case oscar::LAUNCH_START: {
            try {
              // A registry that restarted after a crash must never start a module twice.
              if (const auto running = supervisor.pid_of(q.module_name());
                  running && kill(*running, 0) == 0) {
                throw std::runtime_error(fmt::format("cannot start {}: already running as pid {}",
                                                     q.module_name(), *running));
              }
              // The command comes from this monitor's own system file: a request names only the
              // module, its incarnation and the configuration it restores.
              const auto args =
                  oscar::launch_command(system, host, q.module_name(), q.incarnation(), q.restore(),
                                        log_dir, oscar::sibling_program);
              const auto pid = supervisor.start(q.module_name(), q.incarnation(), args,
                                                {"OSCAR_RUN_DIR=" + log_dir});
              spdlog::info("started {} (incarnation {}, pid {})", q.module_name(), q.incarnation(),
                           pid);
              events.write(event(host, q.module_name(), q.incarnation(), oscar::PROC_STARTED, pid));
            } catch (const std::exception& e) {
              spdlog::error("{}", e.what());
              auto ev = event(host, q.module_name(), q.incarnation(), oscar::PROC_START_FAILED, 0);
              ev.detail(e.what());
              events.write(ev);
            }
            break;
          }
          case oscar::LAUNCH_KILL:
            spdlog::warn("killing {} (the registry saw it hang)", q.module_name());
            supervisor.signal(q.module_name(), SIGKILL);
            break;
          case oscar::LAUNCH_STOP:
            supervisor.signal(q.module_name(), SIGTERM);
            supervisor.signal(q.module_name(), SIGCONT);
            stopping[q.module_name()] = Clock::now() + std::chrono::seconds(5);
            break;
          case oscar::LAUNCH_EXIT:
            exit_requested = true;
            break;
        }
      }
      for (auto& [module, deadline] : stopping) {
        if (Clock::now() > deadline) supervisor.signal(module, SIGKILL);
      }
      for (const auto& x : supervisor.reap()) {
        stopping.erase(x.module);
        spdlog::log(
            x.signal == SIGTERM || x.exit_code == 0 ? spdlog::level::info : spdlog::level::warn,
            "{} (pid {}) {}", x.module, x.pid, x.describe());
        report_exit(x);
        janitor.after_death(x.module);
      }
      janitor.tick();
#if OSCAR_ZERO_COPY
      if (roudi) roudi->tick();
#endif
      if (auto now = report(host, own_pid, supervisor);
          !same_children(now, last_report) || Clock::now() >= next_report) {
        reports.write(now);
        last_report = std::move(now);
        next_report = Clock::now() + system.lease / 3;
      }
    }
    beater.request_stop();
    beater.join();
    stop_modules();
#if OSCAR_ZERO_COPY
    roudi.reset();  // after the modules: a stopping RouDi sends SIGTERM to those that joined it
#endif
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-monitor: %s\n", e.what());
    code = 2;
  }
  // Its participant is gone now: what it, its modules and the rest of the system left goes too.
  if (domain >= 0) {
    if (const auto n = oscar::remove_files_of_dead_processes(domain); n > 0) {
      spdlog::info("removed {} shared-memory files of processes that ended", n);
    }
  }
  if (code == 0) spdlog::info("stopped");
  return code;
}
