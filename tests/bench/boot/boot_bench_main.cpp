// oscar bench boot: how long `oscar boot` takes a system of M modules on H hosts to `running`
// (static peers or a discovery server; the other hosts reached through test-host namespaces or
// over ssh), and how long one module's restart takes in the booted system. Prints a table, or
// JSON with --json. Never decides pass/fail by time: it reports what it measured.
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "bench_system.hpp"  // tests/common
#include "oscar/process_util.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/time.hpp"
#include "percentile.hpp"   // tests/common
#include "process.hpp"      // tests/common
#include "process_cpu.hpp"  // tests/common
#include "ssh_hosts.hpp"    // tests/netns
#include "test_hosts.hpp"   // tests/netns

namespace {
using namespace std::chrono_literals;
using oscar::test::module_of;
using oscar::test::percentile;

struct Options {
  int hosts = 1;
  int modules = 20;
  int runs = 3;
  bool ssh = false;
  bool discovery_server = false;
  bool security = false;
  std::string lease = "1s";
  int timeout_s = 120;
  std::uint32_t shm_segment_bytes = 0;  ///< network.shm_segment_bytes; 0: unset
};

// The test hosts of a run (none for one host): h1 runs boot and the registry, h2..hH are reached
// through `ip netns exec` or, with --ssh, only over ssh.
class Hosts {
 public:
  explicit Hosts(const Options& o) {
    if (o.hosts == 1) return;
    hosts_ = std::make_unique<oscar::test::TestHosts>(o.hosts);
    if (o.ssh) {
      ssh_ = std::make_unique<oscar::test::SshHosts>(*hosts_);
      for (int h = 2; h <= o.hosts; ++h) ssh_->serve(h);
    }
  }

  std::string yaml(const Options& o) const {
    if (!hosts_) return "";
    std::string out = fmt::format("hosts:\n  h1: {{ local: true, address: {} }}\n", address(1));
    for (int h = 2; h <= o.hosts; ++h) {
      out += ssh_ ? fmt::format("  h{}: {}\n", h, ssh_->entry(h))
                  : fmt::format("  h{}: {{ netns: {}, address: {} }}\n", h, hosts_->netns(h),
                                address(h));
    }
    return out;
  }
  std::vector<std::string> on_local_host() const {
    return hosts_ ? hosts_->on(1) : std::vector<std::string>{};
  }
  std::string local_netns() const { return hosts_ ? hosts_->netns(1) : ""; }
  std::string address(int h) const { return hosts_->address(h); }

 private:
  std::unique_ptr<oscar::test::TestHosts> hosts_;
  std::unique_ptr<oscar::test::SshHosts> ssh_;
};

// This thread's network namespace is test host h1's while one lives, so the benchmark's own
// participant (and the threads Fast DDS starts for it) sees the system as boot does.
class InNetns {
 public:
  explicit InNetns(const std::string& netns) {
    if (netns.empty()) return;
    own_ = open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
    const int target = open(("/run/netns/" + netns).c_str(), O_RDONLY | O_CLOEXEC);
    if (own_ < 0 || target < 0 || setns(target, CLONE_NEWNET) != 0) {
      throw std::runtime_error("cannot enter the network namespace " + netns);
    }
    close(target);
  }
  ~InNetns() {
    if (own_ < 0) return;
    (void)!setns(own_, CLONE_NEWNET);
    close(own_);
  }
  InNetns(const InNetns&) = delete;
  InNetns& operator=(const InNetns&) = delete;

 private:
  int own_ = -1;
};

// M modules, sources and the sinks that read them, spread over the hosts in turn.
std::string system_yaml(const Options& o, const Hosts& hosts) {
  std::string yaml = fmt::format("system: bench_boot\nlease: {}\n", o.lease);
  yaml += hosts.yaml(o);
  std::vector<std::string> network;
  if (o.discovery_server) network.push_back("discovery: server");
  if (o.shm_segment_bytes != 0) {
    network.push_back(fmt::format("shm_segment_bytes: {}", o.shm_segment_bytes));
  }
  if (!network.empty()) yaml += fmt::format("network: {{ {} }}\n", fmt::join(network, ", "));
  yaml += "modules:\n";
  for (int i = 0; i < o.modules; ++i) {
    const bool source = i % 2 == 0;
    const auto host = o.hosts > 1 ? fmt::format("host: h{}, ", 1 + i % o.hosts) : "";
    yaml += fmt::format(
        "  - {{ name: m{}, {}kernels: [ {{ type: {}, name: k{}, params: {{ type: Bool }}{} }} ], "
        "mode: {}, restart: {{ max: 1000 }} }}\n",
        i, host, source ? "bench_source" : "bench_sink", i,
        source ? "" : fmt::format(", inputs: {{ in: k{}/out }}", i - 1),
        source ? "{ continuous: 100ms }" : "single_step");
  }
  return yaml;
}

// kill -9 of `module` until the registry reports the system running with its next incarnation.
double restart_ms(oscar::RegistryClient& registry, const std::string& module) {
  const auto before =
      registry.wait_for([](const oscar::SystemState& s) { return s.state() == "running"; }, 30s);
  if (!before || !module_of(*before, module)) throw std::runtime_error("the system is not running");
  const auto incarnation = module_of(*before, module)->incarnation();
  const auto t0 = oscar::wall_now();
  kill(static_cast<pid_t>(module_of(*before, module)->pid()), SIGKILL);
  const auto back = registry.wait_for(
      [&](const oscar::SystemState& s) {
        const auto* m = module_of(s, module);
        return s.state() == "running" && m && m->incarnation() > incarnation;
      },
      60s);
  if (!back) throw std::runtime_error(module + " was not running again within 60 s");
  return static_cast<double>(back->stamp_ns() - t0) / 1e6;
}

struct Figures {
  std::vector<double> boot_ms, restart_ms;
  /// The machine's busy CPU-seconds from boot's start until the bench saw it report running
  /// (within 50 ms): every process of the system on every test host, and whatever else runs.
  std::vector<double> machine_cpu_s;
  /// At the same moment, what each program of the system had used since its processes started.
  std::vector<std::map<std::string, oscar::test::ProgramCpu>> programs;
};

// The programs of a booted system and the ssh connections to its hosts, by process name (the
// benchmark itself is not one of them).
bool part_of_the_boot(const std::string& name) {
  return (name.starts_with("oscar-") && !name.starts_with("oscar-bench")) || name == "ssh" ||
         name == "sshd";
}

// A program's share of the boots: the p50 over the runs of its CPU-seconds at running (0 in a
// run without it), and the most processes it had.
struct ProgramFigure {
  std::string name;
  double cpu_s_p50 = 0;
  int processes = 0;
};

// The costliest first.
std::vector<ProgramFigure> program_figures(const Figures& f) {
  std::map<std::string, int> processes;
  for (const auto& run : f.programs) {
    for (const auto& [name, cpu] : run) processes[name] = std::max(processes[name], cpu.processes);
  }
  std::vector<ProgramFigure> out;
  for (const auto& [name, most] : processes) {
    std::vector<double> seconds;
    for (const auto& run : f.programs) {
      const auto it = run.find(name);
      seconds.push_back(it == run.end() ? 0.0 : it->second.seconds);
    }
    out.push_back({name, percentile(seconds, 0.5), most});
  }
  std::sort(out.begin(), out.end(),
            [](const auto& a, const auto& b) { return a.cpu_s_p50 > b.cpu_s_p50; });
  return out;
}

// One boot: the time boot reports to `running`, then one module's restart (the last sink),
// then Ctrl-C.
void run_once(const Options& o, const Hosts& hosts, const std::string& file,
              const std::string& keystore, int run, Figures& f) {
  const auto restarted = fmt::format("m{}", o.modules % 2 == 0 ? o.modules - 1 : o.modules - 2);
  const int domain = oscar::test::test_domain();
  auto argv = hosts.on_local_host();
  argv.insert(
      argv.end(),
      {oscar::sibling_program("oscar-boot"), file, "--domain", std::to_string(domain), "--log-dir",
       oscar::test::temp_path("bench_boot_logs"), "--timeout", std::to_string(o.timeout_s)});
  if (!keystore.empty()) argv.insert(argv.end(), {"--keystore", keystore});
  // A log of its own per run: the last run's log must not be read before this one truncates it.
  const auto log = oscar::test::temp_path(fmt::format("bench_boot_{}", run)) + ".log";
  const double busy_before = oscar::test::machine_busy_cpu_seconds();
  oscar::test::Process boot(argv, log);
  const std::regex running("running after ([0-9]+) ms");
  std::smatch m;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(o.timeout_s + 30);
  for (std::string out;; std::this_thread::sleep_for(50ms)) {
    out = boot.output();
    if (std::regex_search(out, m, running)) {
      f.boot_ms.push_back(std::stod(m[1]));
      f.machine_cpu_s.push_back(oscar::test::machine_busy_cpu_seconds() - busy_before);
      f.programs.push_back(oscar::test::cpu_by_program(part_of_the_boot));
      break;
    }
    if (boot.wait(0ms) || std::chrono::steady_clock::now() > until) {
      throw std::runtime_error(
          fmt::format("boot of {} modules did not reach running:\n{}", o.modules, out));
    }
  }
  {
    InNetns in(hosts.local_netns());
    const auto system = oscar::SystemSpec::load(file);
    auto network = system.network_for(system.local_host().name, "operator");
    if (!keystore.empty()) network.security = oscar::ParticipantSecurity{keystore, "operator"};
    oscar::DdsParticipant participant(domain, "bench-boot", network);
    oscar::RegistryClient registry(participant, "bench");
    f.restart_ms.push_back(restart_ms(registry, restarted));
  }
  kill(boot.pid(), SIGINT);
  if (!boot.wait(60s)) throw std::runtime_error("boot did not end within 60 s of Ctrl-C");
  std::filesystem::remove(log);  // kept after a failure
  std::fprintf(stderr, "run %d/%d: running after %.0f ms; %s running again %.0f ms after kill -9\n",
               run + 1, o.runs, f.boot_ms.back(), restarted.c_str(), f.restart_ms.back());
}

std::string program_json(const std::vector<ProgramFigure>& programs) {
  std::vector<std::string> entries;
  for (const auto& p : programs)
    entries.push_back(fmt::format("\"{}\":{:.2f}", p.name, p.cpu_s_p50));
  return fmt::format("{}", fmt::join(entries, ","));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench boot: time to running of a booted system, and one module's restart"};
  Options o;
  bool json = false;
  app.add_option("--hosts", o.hosts, "hosts (1: this one; more: test hosts, needs root)")
      ->check(CLI::Range(1, 20));
  app.add_option("--modules", o.modules, "modules, one process each, spread over the hosts")
      ->check(CLI::Range(2, 200));
  app.add_option("--runs", o.runs, "boots to time")->check(CLI::PositiveNumber);
  app.add_flag("--ssh", o.ssh, "reach hosts 2..H only over ssh (an sshd on each test host)");
  app.add_flag("--discovery-server", o.discovery_server,
               "discovery through a server boot starts, not static peers");
  app.add_flag("--security", o.security,
               "with DDS Security: a keystore made here (oscar security init) for the system");
  app.add_option("--lease", o.lease, "the system's lease (a duration, e.g. 300ms, 2s)");
  app.add_option("--timeout", o.timeout_s, "seconds boot waits for every module")
      ->check(CLI::PositiveNumber);
  app.add_option("--shm-segment-bytes", o.shm_segment_bytes,
                 "every participant's shared-memory segment (network.shm_segment_bytes; default: "
                 "by what each sends)")
      ->check(CLI::Range(65536, 1 << 30));
  app.add_flag("--json", json, "print one JSON line");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  if (o.ssh && o.hosts < 2) {
    std::fprintf(stderr, "oscar bench boot: --ssh needs --hosts 2 or more\n");
    return 2;
  }
  // Exit code 3: this machine cannot make what was asked for (the tests skip on it).
  if (o.hosts > 1) {
    if (const auto why = oscar::test::TestHosts::unavailable(); !why.empty()) {
      std::fprintf(stderr, "oscar bench boot: --hosts %d: test hosts %s\n", o.hosts, why.c_str());
      return 3;
    }
  }
  if (o.ssh) {
    if (const auto why = oscar::test::SshHosts::unavailable(); !why.empty()) {
      std::fprintf(stderr, "oscar bench boot: --ssh %s\n", why.c_str());
      return 3;
    }
  }
  try {
    const Hosts hosts(o);
    const auto file = oscar::test::temp_path("bench_boot") + ".yaml";
    std::ofstream(file) << system_yaml(o, hosts);
    const auto keystore = o.security ? oscar::test::make_bench_keystore(file, "bench_boot") : "";
    Figures f;
    for (int run = 0; run < o.runs; ++run) run_once(o, hosts, file, keystore, run, f);
    if (!keystore.empty()) std::filesystem::remove_all(keystore);
    const char* discovery = o.discovery_server ? "server" : "static";
    const auto programs = program_figures(f);
    if (json) {
      std::printf(
          "{\"hosts\":%d,\"modules\":%d,\"ssh\":%s,\"discovery\":\"%s\",\"security\":%s,\"boot_ms_"
          "p50\":%.0f,"
          "\"boot_ms_max\":%.0f,\"restart_ms_p50\":%.0f,\"runs\":%d,"
          "\"machine_cpu_s_until_running_p50\":%.1f,\"cores\":%ld,\"shm_segment_bytes\":%u,"
          "\"program_cpu_s_at_running_p50\":{%s}}\n",
          o.hosts, o.modules, o.ssh ? "true" : "false", discovery, o.security ? "true" : "false",
          percentile(f.boot_ms, 0.5), percentile(f.boot_ms, 1.0), percentile(f.restart_ms, 0.5),
          o.runs, percentile(f.machine_cpu_s, 0.5), sysconf(_SC_NPROCESSORS_ONLN),
          o.shm_segment_bytes, program_json(programs).c_str());
    } else {
      std::printf(
          "oscar bench boot: %d modules on %d host%s%s, %s discovery%s, lease %s, %d runs\n",
          o.modules, o.hosts, o.hosts == 1 ? "" : "s", o.ssh ? " (over ssh)" : "", discovery,
          o.security ? ", DDS Security" : "", o.lease.c_str(), o.runs);
      std::printf("  boot to running: p50 %.0f ms, max %.0f ms\n", percentile(f.boot_ms, 0.5),
                  percentile(f.boot_ms, 1.0));
      std::printf(
          "  CPU the machine spent until then (all its %ld cores, every process): p50 %.1f s\n",
          sysconf(_SC_NPROCESSORS_ONLN), percentile(f.machine_cpu_s, 0.5));
      std::printf("  of it, by program (p50; its processes):");
      for (const auto& p : programs) {
        std::printf(" %s %.2f s (%d)", p.name.c_str(), p.cpu_s_p50, p.processes);
      }
      std::printf("\n");
      std::printf("  restart of one module (kill -9 to running): p50 %.0f ms\n",
                  percentile(f.restart_ms, 0.5));
    }
    std::filesystem::remove(file);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench boot: %s\n", e.what());
    return 2;
  }
}
