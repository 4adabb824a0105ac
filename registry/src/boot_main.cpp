// oscar-boot (`oscar boot SYSTEM.yaml`): checks a system file, starts the registry and one
// monitor per host, waits until every module is announced, follows the merged log until
// Ctrl-C (or --duration), then shuts the system down in order and leaves no process behind.
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <oscar/configPubSubTypes.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/coordinator/applet_system.hpp"
#include "oscar/coordinator/swarm_setup.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/process_util.hpp"
#include "oscar/registry/clock_topics.hpp"
#include "oscar/registry/host_check.hpp"
#include "oscar/registry/launch_command.hpp"
#include "oscar/registry/log_printer.hpp"
#include "oscar/registry/registry.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/run_command.hpp"
#include "oscar/registry/running_systems.hpp"
#include "oscar/registry/supervisor.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/security_files.hpp"
#include "oscar/shared_memory.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "restart_budget.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// A netns host must exist before anything starts (tests and operators create them).
void check_hosts(const oscar::SystemSpec& system) {
  for (const auto& h : system.hosts) {
    if (h.kind == oscar::HostSpec::Kind::kNetns &&
        !std::filesystem::exists("/var/run/netns/" + h.netns)) {
      throw std::invalid_argument(fmt::format(
          "{}: host '{}': network namespace '{}' does not exist (create it: ip netns add {})",
          h.where, h.name, h.netns, h.netns));
    }
  }
}

// With a keystore, every process of the system must find its identity there before anything
// starts: a module without one would fail at each restart with the rest of the system running.
void check_identities(const oscar::SystemSpec& system, const std::string& keystore) {
  namespace sf = oscar::security_files;
  std::vector<std::string> identities{sf::kRegistry, sf::kBoot};
  for (const auto& h : system.hosts) identities.push_back(sf::monitor_identity(h.name));
  for (const auto& m : system.modules) identities.push_back(sf::module_identity(m.spec.name));
  for (const auto& identity : identities) sf::dds_security_properties(keystore, identity);
}

// Every ssh host at once, before anything starts anywhere: reachable, the same OSCAR, the same
// system file (copied there first if asked), every program and plugin of its modules there
// (oscar-monitor --check).
void check_ssh_hosts(const oscar::SystemSpec& system, const std::string& file, bool copy) {
  const auto monitor = oscar::sibling_program("oscar-monitor");
  const auto content = oscar::read_text_file(file);
  std::vector<std::future<std::optional<std::string>>> answers;
  for (const auto& h : system.hosts) {
    if (h.kind != oscar::HostSpec::Kind::kSsh) continue;
    answers.push_back(std::async(std::launch::async, [&, h]() -> std::optional<std::string> {
      // ssh gives up connecting after 10 s (ConnectTimeout); loading plugins takes well under.
      constexpr std::chrono::seconds kTimeout{30};
      if (copy) {
        const auto put =
            oscar::run_command(oscar::copy_system_file_command(h, file), kTimeout, content);
        if (put.exit_code == 255 || put.exit_code == -1) {
          return oscar::explain_host_check(h, monitor, put.exit_code, put.output);
        }
        if (put.exit_code != 0) {
          return fmt::format("host '{}' ({}): could not copy the system file to {} there: {}",
                             h.name, h.ssh, file, put.output);
        }
      }
      const auto run = oscar::run_command(oscar::host_check_command(h, file, monitor), kTimeout);
      return oscar::explain_host_check(h, monitor, run.exit_code, run.output);
    }));
  }
  std::vector<std::string> problems;
  for (auto& a : answers) {
    if (auto problem = a.get()) problems.push_back(std::move(*problem));
  }
  if (!problems.empty()) {
    throw std::runtime_error(fmt::format("{} ssh host{} not ready, nothing started:\n  {}",
                                         problems.size(), problems.size() == 1 ? " is" : "s are",
                                         fmt::join(problems, "\n  ")));
  }
}

// The modules that do not run, the first few by name: a system of a hundred modules would
// otherwise print lines of a hundred names.
std::string summary(const oscar::SystemState& s) {
  constexpr std::size_t kNamed = 8;
  std::vector<std::string> parts;
  std::size_t others = 0;
  for (const auto& m : s.modules()) {
    if (m.status() == "running") continue;
    if (parts.size() < kNamed) {
      parts.push_back(m.name() + " " + m.status());
    } else {
      ++others;
    }
  }
  if (others > 0) parts.push_back(fmt::format("and {} more", others));
  return parts.empty() ? std::string() : " [" + fmt::format("{}", fmt::join(parts, ", ")) + "]";
}

// While booting, one line per module that comes up (not one per launch, start and announcement).
std::string booting_progress(const oscar::SystemState& s) {
  const auto running = std::count_if(s.modules().begin(), s.modules().end(),
                                     [](const auto& m) { return m.status() == "running"; });
  return fmt::format("system booting: {} of {} modules running", running, s.modules().size());
}

std::string final_line(const std::string& text) {
  const auto end = text.find_last_not_of('\n');
  if (end == std::string::npos) return {};
  const auto newline = text.rfind('\n', end);
  const auto begin = newline == std::string::npos ? 0 : newline + 1;
  return text.substr(begin, end + 1 - begin);
}

// Refuses to boot onto a domain where processes of another system already run (a registry,
// monitors or modules, also ones a killed boot left behind): both systems would run every module
// and one's shutdown would stop the other. A loaded machine may answer later than the window:
// the registry looks on until it starts the first module (Registry::domain_free).
void check_domain_free(const oscar::DdsParticipant& participant) {
  std::this_thread::sleep_for(oscar::kDiscoveryWindow);
  if (oscar::other_systems_on_domain(participant).empty()) return;
  throw std::runtime_error(
      oscar::domain_in_use(participant.domain(), oscar::other_systems_in_full(participant)));
}

// Ctrl-C (SIGINT) and SIGTERM, counted: the first stops the system in order, the second aborts.
class StopRequests {
 public:
  explicit StopRequests(sigset_t signals) : signals_(signals) {}
  /// Sleeps up to `timeout`, or until a stop request comes (counted).
  void wait(std::chrono::milliseconds timeout) {
    if (oscar::wait_for_stop(signals_, timeout)) ++count_;
  }
  int count() const { return count_; }

 private:
  sigset_t signals_;
  int count_ = 0;
};

// Waits until `done()`, `timeout` or one more stop request than `requests` had at the start,
// printing the merged log meanwhile. True if `done()` came true.
bool wait_until(const std::function<bool()>& done, Clock::duration timeout, StopRequests& requests,
                oscar::LogPrinter& log) {
  const int before = requests.count();
  const auto until =
      timeout == Clock::duration::max() ? Clock::time_point::max() : Clock::now() + timeout;
  while (!done()) {
    if (requests.count() > before || Clock::now() >= until) return false;
    requests.wait(std::chrono::milliseconds(50));
    log.flush();
  }
  return true;
}

// The discovery servers of a system whose network says `discovery: server`, by process name,
// each with its command line; they run on the local host (where boot runs).
std::map<std::string, std::vector<std::string>> discovery_servers(const oscar::SystemSpec& system,
                                                                  const std::string& file,
                                                                  const std::string& domain) {
  const auto& local = system.local_host();
  const auto network = oscar::NetworkConfig::for_host(system.root, local.name);
  std::map<std::string, std::vector<std::string>> servers;
  if (network.discovery != oscar::Discovery::kServer) return servers;
  for (std::size_t i = 0; i < network.discovery_servers.size(); ++i) {
    servers["discovery-server-" + std::to_string(i)] = oscar::on_host(
        local, {oscar::sibling_program("oscar-discovery-server"), "--system", file, "--host",
                local.name, "--domain", domain, "--index", std::to_string(i)});
  }
  return servers;
}

// A registry that dies while the system runs is started again (with --recover) at most this
// often within the window; then boot gives up and stops the system (docs/boot.md).
constexpr int kRegistryRestarts = 5;
constexpr std::chrono::seconds kRegistryRestartWindow{60};

std::chrono::milliseconds seconds(double s) {
  return std::chrono::milliseconds(static_cast<long>(s * 1000));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar boot: boots a system of modules across hosts from one YAML file"};
  std::string file, log_dir, keystore_flag;
  int domain = -1;
  double timeout_s = 30, duration_s = 0;
  bool check = false;
  app.add_option("system", file, "the system file (docs/boot.md)")->required();
  app.add_option("-d,--domain", domain, "DDS domain (default: the file's)");
  app.add_option("--timeout", timeout_s, "seconds to wait until every module is announced");
  app.add_option("--duration", duration_s, "stop after this many seconds (default: Ctrl-C)");
  app.add_option("--log-dir", log_dir, "where process output goes (default /tmp/oscar/...)");
  app.add_option("--keystore", keystore_flag,
                 "DDS Security keystore for every process (default: the file's security: "
                 "keystore:; docs/security.md)");
  app.add_flag("--check", check, "check the system file and its modules, start nothing");
  bool copy_system_file = false;
  app.add_flag("--copy-system-file", copy_system_file,
               "copy the system file to every ssh host, to the same path, before checking it");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  StopRequests stop(oscar::block_stop_signals());

  oscar::LogPrinter log(stdout, isatty(1) != 0);
  try {
    if (!keystore_flag.empty()) {
      if (!std::filesystem::is_directory(keystore_flag)) {
        throw std::invalid_argument(fmt::format(
            "--keystore {}: no such folder (make it: oscar security init {} --keystore {})",
            keystore_flag, file, keystore_flag));
      }
      // Every process boot starts, and each module its monitor starts, inherits it.
      setenv("OSCAR_KEYSTORE", std::filesystem::absolute(keystore_flag).c_str(), 1);
    }
    auto system = oscar::SystemSpec::load(file);
    if (domain >= 0) system.override_domain(domain);
    const auto keystore = system.keystore();
    if (!keystore.empty()) check_identities(system, keystore);
    oscar::register_standard_cue_types();
    system.check_modules(oscar::plugin_search_path());
    oscar::coordinator::check_applets(system, oscar::plugin_search_path());
    // The live swarm's section, read as the coordinator will read it: else a bad one would only
    // fail the coordinator, again at each restart, with the rest of the system running.
    oscar::coordinator::SwarmSetup::from(system);
    const auto& local = system.local_host();
    check_hosts(system);
    const bool hosts_here =
        std::any_of(system.hosts.begin(), system.hosts.end(), [](const auto& h) {
          return h.kind != oscar::HostSpec::Kind::kSsh;  // an ssh host's check asks there
        });
    if (system.zero_copy && hosts_here) {
      if (const auto problem = oscar::zero_copy_unavailable()) {
        throw std::invalid_argument(fmt::format("{}: {}", system.zero_copy->where, *problem));
      }
    }
    // Remote hosts read the file at the same path: an absolute one.
    const auto remote_file = std::filesystem::absolute(file).lexically_normal().string();
    check_ssh_hosts(system, remote_file, copy_system_file);
    stop.wait(std::chrono::milliseconds(0));  // Ctrl-C while the hosts were checked
    if (stop.count() > 0) {
      std::fprintf(stderr, "oscar boot: Ctrl-C: nothing started\n");
      return 130;
    }
    if (check) {
      std::printf("%s: system '%s', %zu modules on %zu hosts: ok\n", file.c_str(),
                  system.name.c_str(), system.modules.size(), system.hosts.size());
      return 0;
    }
    if (log_dir.empty()) log_dir = fmt::format("/tmp/oscar/{}-{}", system.name, system.domain);
    const auto started = Clock::now();
    // This machine's record of the domain first (at once, and exact), then what discovery sees.
    const oscar::RunningSystemRecord record(
        {.domain = system.domain,
         .system = system.name,
         .file = file,
         .log_dir = log_dir,
         .keystore = keystore,
         .boot_pid = getpid(),
         .started = static_cast<long long>(std::time(nullptr))});
    // Boot outlives its participant only by a moment: the port semaphores Fast DDS leaves when it
    // ends are removed by the next boot, with whatever else ended processes left.
    oscar::remove_files_of_dead_processes(system.domain);
    // Every process of this boot says so in discovery (its children inherit the variable), which
    // tells them from another system's on the same domain.
    char host_name[256] = "";
    gethostname(host_name, sizeof host_name - 1);
    const auto instance = fmt::format("{}@{}:{}:{}", system.name, host_name, getpid(),
                                      std::chrono::duration_cast<std::chrono::milliseconds>(
                                          std::chrono::system_clock::now().time_since_epoch())
                                          .count());
    setenv(oscar::kSystemInstanceEnv, instance.c_str(), 1);
    oscar::DdsParticipant participant(system.domain, "oscar-boot",
                                      system.network_for(local.name, oscar::security_files::kBoot));
    std::mutex state_mutex;  // DDS may call back from its UDP and shared-memory threads
    std::string last_line;
    bool booted = false;  // states before are another system's
    // This system's newest state: another registry on the domain (one that refuses to start
    // anything, having found this system) publishes its own system's.
    std::optional<oscar::SystemState> state;
    oscar::RegistryClient registry(participant, "boot", [&](const oscar::SystemState& s) {
      if (s.system() != system.name) return;
      auto line = s.state() == "booting"
                      ? booting_progress(s)
                      : fmt::format("system {}: {}{}", s.state(), s.message(), summary(s));
      std::lock_guard lock(state_mutex);
      state = s;
      if (booted && line != last_line) {
        log.note("registry", line, s.state() == "suspended" ? oscar::LOG_WARN : oscar::LOG_INFO);
        last_line = std::move(line);
      }
    });
    check_domain_free(participant);
    // A new boot numbers cues from 1 again; only restarts within it continue the numbering.
    std::error_code ec;
    for (const auto& e : std::filesystem::recursive_directory_iterator(log_dir, ec)) {
      if (e.path().extension() == ".seq") std::filesystem::remove(e.path(), ec);
    }
    log.note("boot", fmt::format("booting '{}' from {}: {} modules on {} hosts, domain {}, logs "
                                 "in {}",
                                 system.name, file, system.modules.size(), system.hosts.size(),
                                 system.domain, log_dir));
    if (keystore.empty()) {
      log.note("boot",
               fmt::format("unauthenticated: the system runs without DDS Security, so any process "
                           "that reaches domain {} can read its cues, configure its modules and "
                           "stop it (a keystore: oscar security init, then oscar boot --keystore "
                           "DIR; docs/security.md)",
                           system.domain),
               oscar::LOG_WARN);
    } else {
      log.note("boot", fmt::format("secured with keystore {}: every process authenticates as its "
                                   "own identity",
                                   keystore));
    }
    {
      std::lock_guard lock(state_mutex);
      booted = true;
    }
    // Records are ordered by their host's corrected time once its monitor has measured its
    // clock (docs/boot.md, "Clocks").
    for (const auto& m : system.modules) log.module_host(m.spec.name, m.spec.host);
    oscar::TopicReader<oscar::HostClock, oscar::HostClockPubSubType> host_clocks(
        participant, oscar::topics::host_clocks(), [&](const oscar::HostClock& c, const auto&) {
          log.host_clock(c.host(), std::chrono::nanoseconds(c.offset_ns()),
                         std::chrono::nanoseconds(c.uncertainty_ns()));
        });
    oscar::TopicReader<oscar::LogRecord, oscar::LogRecordPubSubType> logs(
        participant, oscar::topics::log(),
        [&](const oscar::LogRecord& r, const auto&) { log.add(r); });

    // The discovery servers first (every other participant is their client; stopped last),
    // then the registry (it waits for the monitors), then one monitor per host.
    // Killed itself (SIGKILL, an OOM kill), boot leaves the system as it would on Ctrl-C: its
    // children get SIGTERM, so the registry and every monitor stop their modules in order (a
    // monitor over ssh sees its connection end), and nothing runs on without boot.
    oscar::Supervisor children(log_dir, SIGTERM);
    const auto dom = std::to_string(system.domain);
    const auto servers = discovery_servers(system, file, dom);
    for (const auto& [name, command] : servers) children.start(name, 1, command);
    // What cannot be learnt from the wire after a crash (docs/boot.md).
    const auto journal = log_dir + "/registry.journal.yaml";
    const std::vector<std::string> registry_command{oscar::sibling_program("oscar-registry"),
                                                    "--system",
                                                    file,
                                                    "--host",
                                                    local.name,
                                                    "--domain",
                                                    dom,
                                                    "--journal",
                                                    journal};
    children.start("registry", 1, registry_command);
    for (const auto& h : system.hosts) {
      const bool remote = h.kind == oscar::HostSpec::Kind::kSsh;
      const auto& host_file = remote ? remote_file : file;
      std::vector<std::string> monitor{oscar::sibling_program("oscar-monitor"), "--system",
                                       host_file};
      if (remote) {
        // ssh passes no environment: the system instance and the keystore (at the same path
        // there) are said explicitly.
        std::vector<std::string> env{"env",
                                     fmt::format("{}={}", oscar::kSystemInstanceEnv, instance)};
        if (!keystore.empty()) env.push_back("OSCAR_KEYSTORE=" + keystore);
        monitor.insert(monitor.begin(), env.begin(), env.end());
      }
      monitor.insert(monitor.end(),
                     {"--host", h.name, "--domain", dom, "--log-dir", log_dir + "/" + h.name});
      if (remote) monitor.push_back("--over-ssh");
      children.start("monitor-" + h.name, 1, oscar::on_host(h, monitor));
    }
    const auto latest = [&] {
      std::lock_guard lock(state_mutex);
      return state;
    };
    const auto state_is = [&](const char* name) {
      const auto s = latest();
      return s && s->state() == name;
    };
    bool registry_gone = false;
    bool registry_ended_orderly = false;  // exit code 0, asked by someone other than boot
    bool registry_given_up = false;       // it died too often
    std::string domain_in_use;            // the registry found another system: what it said
    oscar::internal::RestartBudget registry_restarts;
    bool shutting_down = false;
    // A registry killed or crashed while the system runs is started again: the modules go on
    // meanwhile, and the new one adopts them (oscar-registry --recover).
    const auto restart_registry = [&](const oscar::ProcessExit& x) {
      const auto now = Clock::now();
      if (!registry_restarts.allows(now, kRegistryRestarts, kRegistryRestartWindow)) {
        log.note("boot",
                 fmt::format("registry died ({}) for the {}th time within {} s: giving up, "
                             "stopping the system",
                             x.describe(), kRegistryRestarts + 1, kRegistryRestartWindow.count()),
                 oscar::LOG_ERROR);
        return false;
      }
      registry_restarts.record(now);
      log.note("boot",
               fmt::format("registry died ({}): restarting it ({} of {} in {} s)", x.describe(),
                           registry_restarts.within(now, kRegistryRestartWindow), kRegistryRestarts,
                           kRegistryRestartWindow.count()),
               oscar::LOG_WARN);
      auto command = registry_command;
      command.push_back("--recover");
      children.start("registry", x.incarnation + 1, command);
      return true;
    };
    const auto registry_exited = [&] {
      for (const auto& x : children.reap()) {
        // Code 0 is an orderly end (oscar shutdown, SIGTERM), also when its 'stopped' state
        // has not reached boot yet.
        // (A registry that dies while the system runs is reported where it is restarted.)
        if (x.exit_code != 0 && (x.module != "registry" || shutting_down)) {
          log.note("boot", fmt::format("{} {}", x.module, x.describe()), oscar::LOG_ERROR);
        }
        // A discovery server that died is started again: its clients find it at its address and
        // tell it again what they have (meanwhile the other one, if any, serves them).
        if (const auto it = servers.find(x.module); it != servers.end() && !shutting_down) {
          log.note("boot", fmt::format("restarting {}", x.module), oscar::LOG_WARN);
          children.start(x.module, x.incarnation + 1, it->second);
        }
        if (x.module == "registry") {
          if (x.exit_code == oscar::kDomainInUseExit && !shutting_down) {
            domain_in_use = final_line(x.last_output);  // "oscar-registry: domain 7 is in use..."
            if (domain_in_use.empty()) domain_in_use = "registry " + x.describe();
          } else if (x.exit_code != 0 && !shutting_down && restart_registry(x)) {
            continue;
          }
          registry_given_up = x.exit_code != 0 && !shutting_down;
          registry_gone = true;
          registry_ended_orderly = x.exit_code == 0;
        }
      }
      return registry_gone;
    };

    int code = 0;
    const bool running =
        wait_until([&] { return state_is("running") || state_is("stopped") || registry_exited(); },
                   seconds(timeout_s), stop, log);
    if (!domain_in_use.empty()) {
      // Boot's own look found nothing; the registry's, later, did (a loaded machine). No module
      // was started: the monitors are stopped and the other system is left alone.
      log.note("boot", fmt::format("refused: {}", domain_in_use), oscar::LOG_ERROR);
      children.stop_all(std::chrono::milliseconds(5000));
      log.flush(true);
      return 2;
    }
    if (stop.count() > 0) {
      log.note("boot", "Ctrl-C during boot: stopping what has started", oscar::LOG_WARN);
    } else if (!running) {
      const auto last = latest();
      log.note("boot",
               fmt::format("not every module was announced within {} s: {} (their output is in "
                           "{})",
                           timeout_s, last ? last->message() : "no registry answered", log_dir),
               oscar::LOG_ERROR);
      code = 1;
    } else if (state_is("running")) {
      log.note(
          "boot",
          fmt::format("system '{}' running after {} ms (Ctrl-C stops it)", system.name,
                      std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - started)
                          .count()));
      wait_until([&] { return state_is("stopped") || registry_exited(); },
                 duration_s > 0 ? Clock::duration(seconds(duration_s)) : Clock::duration::max(),
                 stop, log);
    }
    if (registry_given_up) code = 1;
    const int stops_before = stop.count();
    shutting_down = true;
    // The registry may exit before its 'stopped' state reaches boot; boot asked it for nothing,
    // so an orderly exit was asked from elsewhere.
    if (state_is("stopped") || (registry_gone && registry_ended_orderly && stop.count() == 0)) {
      log.note("boot", "the system was shut down (oscar shutdown)");
    } else if (!registry_gone) {
      // SIGTERM asks the registry for what `oscar shutdown` asks: stop the modules in reverse
      // boot order, tell the monitors to exit, exit. Boot need not reach it over DDS for that.
      log.note("boot", "shutting down (Ctrl-C aborts)");
      children.signal("registry", SIGTERM);
      wait_until(registry_exited, std::chrono::seconds(30), stop, log);
    }
    stop.wait(std::chrono::milliseconds(0));
    if (stop.count() > stops_before) {
      // Ctrl-C while shutting down: no more waiting for anyone. Modules die with their monitors.
      log.note("boot", "aborted: killing every process of the system", oscar::LOG_WARN);
      children.stop_all(std::chrono::milliseconds(0));
      log.flush(true);
      return 130;
    }
    // Monitors exit when the registry tells them; over ssh their last lines and exit code come
    // back only if boot does not cut the connection first. What is left is stopped here.
    wait_until(
        [&] {
          for (const auto& x : children.reap()) {
            if (x.exit_code != 0) log.note("boot", fmt::format("{} {}", x.module, x.describe()));
          }
          return std::none_of(system.hosts.begin(), system.hosts.end(), [&](const auto& h) {
            return children.pid_of("monitor-" + h.name).has_value();
          });
        },
        std::chrono::seconds(3), stop, log);
    for (const auto& x : children.stop_all(std::chrono::milliseconds(5000))) {
      if (x.exit_code != 0) log.note("boot", fmt::format("{} {}", x.module, x.describe()));
    }
    log.note("boot", "all processes stopped");
    log.flush(true);
    return code;
  } catch (const std::exception& e) {
    log.flush(true);
    std::fprintf(stderr, "oscar boot: %s\n", e.what());
    return 2;
  }
}
