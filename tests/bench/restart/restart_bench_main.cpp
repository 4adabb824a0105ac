// oscar bench restart: how fast the registry notices a failure and has the system running
// again (issue 3), how fast a killed registry is back with every module running
// (--registry-kills, issue 19), and how long booting 20 modules on 3 test hosts takes. With
// --security, the same again on systems booted with a keystore the benchmark makes (`oscar security
// init`), alternated with the plain ones in one run, and the ratios. Prints a table, or JSON with
// --json. Never decides pass/fail by time: it reports what it measured.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "bench_system.hpp"  // tests/common
#include "oscar/process_util.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/time.hpp"
#include "percentile.hpp"  // tests/common
#include "process.hpp"     // tests/common
#include "test_hosts.hpp"  // tests/netns

namespace {
using namespace std::chrono_literals;

using oscar::test::module_of;
using oscar::test::percentile;

struct Failures {
  std::vector<double> detect_ms, resume_ms;
};

// Fails the modules in turn with `sig` (SIGKILL: a crash; SIGSTOP: a hang) and times, from the
// signal, the registry's first state showing the failure and the state running again.
Failures fail_modules(oscar::RegistryClient& registry, const std::vector<std::string>& modules,
                      int count, int sig) {
  Failures f;
  for (int i = 0; i < count; ++i) {
    const auto& name = modules[static_cast<std::size_t>(i) % modules.size()];
    const auto before =
        registry.wait_for([&](const oscar::SystemState& s) { return s.state() == "running"; }, 30s);
    if (!before) throw std::runtime_error("the system is not running");
    const auto incarnation = module_of(*before, name)->incarnation();
    const auto t0 = oscar::wall_now();
    kill(static_cast<pid_t>(module_of(*before, name)->pid()), sig);
    const auto detected = registry.wait_for(
        [&](const oscar::SystemState& s) { return module_of(s, name)->status() != "running"; },
        30s);
    const auto back = registry.wait_for(
        [&](const oscar::SystemState& s) {
          return s.state() == "running" && module_of(s, name)->incarnation() > incarnation;
        },
        30s);
    if (!detected || !back) throw std::runtime_error(name + " did not come back within 30 s");
    f.detect_ms.push_back(static_cast<double>(detected->stamp_ns() - t0) / 1e6);
    f.resume_ms.push_back(static_cast<double>(back->stamp_ns() - t0) / 1e6);
    std::fprintf(stderr, "%s %d/%d (%s): failure seen after %.1f ms, running after %.1f ms\n",
                 sig == SIGKILL ? "kill -9" : "SIGSTOP", i + 1, count, name.c_str(),
                 f.detect_ms.back(), f.resume_ms.back());
  }
  return f;
}

// The pid of the registry of the system in `file` (0 if none runs), from /proc.
long registry_pid(const std::string& file) {
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const auto name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(e.path() / "cmdline");
    std::vector<std::string> args;
    for (std::string arg; std::getline(in, arg, '\0');) args.push_back(arg);
    if (!args.empty() && std::filesystem::path(args[0]).filename() == "oscar-registry" &&
        std::find(args.begin(), args.end(), file) != args.end()) {
      return std::stol(name);
    }
  }
  return 0;
}

// Kills the registry of the system in `file` `count` times and times, from the kill, the new
// registry's first state with every module running again ("registry recovered"). Boot restarts
// a registry at most 5 times within 60 s: beyond 5 kills, each waits until the 5th kill before
// it is a minute old.
std::vector<double> kill_registry(oscar::RegistryClient& registry, const std::string& file,
                                  int count) {
  constexpr std::size_t kBootRestarts = 5;
  constexpr auto kBootWindow = 61s;  // a second more than boot's 60 s
  std::vector<double> back_ms;
  std::vector<std::chrono::steady_clock::time_point> kills;
  for (int i = 0; i < count; ++i) {
    const auto before =
        registry.wait_for([&](const oscar::SystemState& s) { return s.state() == "running"; }, 30s);
    if (!before) throw std::runtime_error("the system is not running");
    if (kills.size() >= kBootRestarts) {
      std::this_thread::sleep_until(kills[kills.size() - kBootRestarts] + kBootWindow);
    }
    const long pid = registry_pid(file);
    if (pid == 0) throw std::runtime_error("no oscar-registry process of " + file);
    const auto t0 = oscar::wall_now();
    kills.push_back(std::chrono::steady_clock::now());
    kill(static_cast<pid_t>(pid), SIGKILL);
    const auto back = registry.wait_for(
        [&](const oscar::SystemState& s) {
          const bool all = std::all_of(s.modules().begin(), s.modules().end(),
                                       [](const auto& m) { return m.status() == "running"; });
          return s.stamp_ns() > static_cast<unsigned long long>(t0) && s.state() == "running" &&
                 s.message().find("registry recovered") != std::string::npos && all;
        },
        60s);
    if (!back) throw std::runtime_error("the killed registry was not back within 60 s");
    back_ms.push_back(static_cast<double>(back->stamp_ns() - t0) / 1e6);
    std::fprintf(stderr, "registry kill -9 %d/%d: every module running after %.1f ms (%s)\n", i + 1,
                 count, back_ms.back(), back->message().c_str());
  }
  return back_ms;
}

// boot's arguments for the system in `file` on `domain`, with `keystore` unless it is empty.
std::vector<std::string> boot_command(const std::string& file, int domain,
                                      const std::string& log_dir, const std::string& keystore) {
  std::vector<std::string> argv{oscar::sibling_program("oscar-boot"),
                                file,
                                "--domain",
                                std::to_string(domain),
                                "--log-dir",
                                log_dir};
  if (!keystore.empty()) argv.insert(argv.end(), {"--keystore", keystore});
  return argv;
}

// Boots `modules` sources/sinks over `hosts` test hosts (or this host), with a keystore if
// `secured`, and returns what oscar boot reports as its time to `running`.
double boot_time_ms(int modules, bool netns, int domain, bool secured) {
  std::unique_ptr<oscar::test::TestHosts> hosts;
  if (netns) hosts = std::make_unique<oscar::test::TestHosts>(3);
  std::string yaml = "system: boot20\nlease: 300ms\n";
  if (netns) {
    yaml += fmt::format("hosts:\n  h1: {{ local: true, address: {} }}\n", hosts->address(1));
    for (int h = 2; h <= 3; ++h) {
      yaml += fmt::format("  h{}: {{ netns: {}, address: {} }}\n", h, hosts->netns(h),
                          hosts->address(h));
    }
  }
  yaml += "modules:\n";
  for (int i = 0; i < modules; ++i) {
    const bool source = i % 2 == 0;
    yaml += fmt::format(
        "  - {{ name: m{}, {}kernels: [ {{ type: {}, name: k{}, params: {{ type: Bool }}{} }} ], "
        "mode: {} }}\n",
        i, netns ? fmt::format("host: h{}, ", 1 + i % 3) : "",
        source ? "bench_source" : "bench_sink", i,
        source ? "" : fmt::format(", inputs: {{ in: k{}/out }}", i - 1),
        source ? "{ continuous: 50ms }" : "single_step");
  }
  const auto file = oscar::test::temp_path("bench_boot20") + ".yaml";
  std::ofstream(file) << yaml;
  const auto keystore = secured ? oscar::test::make_bench_keystore(file, "bench_boot20") : "";
  std::vector<std::string> argv;
  if (netns) argv = hosts->on(1);
  const auto boot_argv =
      boot_command(file, domain, oscar::test::temp_path("bench_boot20_logs"), keystore);
  argv.insert(argv.end(), boot_argv.begin(), boot_argv.end());
  argv.insert(argv.end(), {"--duration", "1"});
  oscar::test::Process boot(argv, oscar::test::temp_path("bench_boot20") + ".log");
  if (boot.wait(120s) != 0)
    throw std::runtime_error("boot of 20 modules failed:\n" + boot.output());
  std::smatch m;
  const auto out = boot.output();
  if (!std::regex_search(out, m, std::regex("running after ([0-9]+) ms"))) {
    throw std::runtime_error("boot did not report its time:\n" + out);
  }
  if (!keystore.empty()) std::filesystem::remove_all(keystore);
  return std::stod(m[1]);
}

// The three-module system the failures are timed on.
constexpr const char* kRestartSystem = R"(system: bench_restart
lease: 300ms
modules:
  - { name: a, kernels: [ { type: bench_source, name: a, params: { type: Bool } } ], mode: { continuous: 10ms }, restart: { max: 100000 } }
  - { name: b, kernels: [ { type: relay, name: b, params: { type: Bool }, inputs: { in: a/out } } ], mode: single_step, restart: { max: 100000 } }
  - { name: c, kernels: [ { type: bench_sink, name: c, params: { type: Bool }, inputs: { in: b/out } } ], mode: single_step, restart: { max: 100000 } }
)";

struct Run {
  Failures crashes, hung;
  std::vector<double> registry_back_ms;
  std::vector<double> boot20_ms;
};

// Boots the three-module system (with a keystore if `secured`) and times `kills` crashes and
// `hangs` hangs of its modules, and `registry_kills` crashes of its registry.
void time_failures(Run& run, int kills, int hangs, int registry_kills, int domain, bool secured) {
  const auto name = std::string(secured ? "bench_restart_secured" : "bench_restart");
  const auto file = oscar::test::temp_path(name) + ".yaml";
  std::ofstream(file) << kRestartSystem;
  const auto keystore = secured ? oscar::test::make_bench_keystore(file, name) : "";
  oscar::test::Process boot(
      boot_command(file, domain, oscar::test::temp_path(name + "_logs"), keystore),
      oscar::test::temp_path(name) + ".log");
  oscar::NetworkConfig network;
  if (secured) network.security = oscar::ParticipantSecurity{keystore, "operator"};
  oscar::DdsParticipant participant(domain, "bench-restart", network);
  oscar::RegistryClient registry(participant, "bench");
  auto append = [](Failures& to, const Failures& f) {
    to.detect_ms.insert(to.detect_ms.end(), f.detect_ms.begin(), f.detect_ms.end());
    to.resume_ms.insert(to.resume_ms.end(), f.resume_ms.begin(), f.resume_ms.end());
  };
  if (kills > 0) append(run.crashes, fail_modules(registry, {"a", "b", "c"}, kills, SIGKILL));
  if (hangs > 0) append(run.hung, fail_modules(registry, {"a", "b", "c"}, hangs, SIGSTOP));
  if (registry_kills > 0) {
    const auto back = kill_registry(registry, file, registry_kills);
    run.registry_back_ms.insert(run.registry_back_ms.end(), back.begin(), back.end());
  }
  kill(boot.pid(), SIGINT);
  boot.wait(60s);
  if (!keystore.empty()) std::filesystem::remove_all(keystore);
}

void print_json(const char* security, const Run& r, int kills, int hangs, int registry_kills,
                int hosts) {
  std::printf(
      "{\"security\":\"%s\",\"kills\":%d,\"detect_ms_p50\":%.1f,\"detect_ms_p99\":%.1f,"
      "\"resume_ms_p50\":%.1f,\"resume_ms_p99\":%.1f,\"hangs\":%d,\"hang_detect_ms_p50\":%.1f,"
      "\"hang_detect_ms_p99\":%.1f,\"hang_resume_ms_p50\":%.1f,\"hang_resume_ms_p99\":%.1f,"
      "\"boot20_ms\":%.0f,\"boot20_runs\":%zu,\"boot20_hosts\":%d,\"lease_ms\":300,"
      "\"backoff_ms\":200,\"registry_kills\":%d,\"registry_back_ms_p50\":%.1f,"
      "\"registry_back_ms_max\":%.1f}\n",
      security, kills, percentile(r.crashes.detect_ms, 0.5), percentile(r.crashes.detect_ms, 0.99),
      percentile(r.crashes.resume_ms, 0.5), percentile(r.crashes.resume_ms, 0.99), hangs,
      percentile(r.hung.detect_ms, 0.5), percentile(r.hung.detect_ms, 0.99),
      percentile(r.hung.resume_ms, 0.5), percentile(r.hung.resume_ms, 0.99),
      percentile(r.boot20_ms, 0.5), r.boot20_ms.size(), hosts, registry_kills,
      percentile(r.registry_back_ms, 0.5), percentile(r.registry_back_ms, 1.0));
}

void print_rows(const char* label, const Run& r, int kills, int hangs, int registry_kills) {
  if (kills > 0) {
    std::printf("%-34s %6d %14.1f %14.1f %14.1f %14.1f\n",
                fmt::format("kill -9 (crash){}", label).c_str(), kills,
                percentile(r.crashes.detect_ms, 0.5), percentile(r.crashes.detect_ms, 0.99),
                percentile(r.crashes.resume_ms, 0.5), percentile(r.crashes.resume_ms, 0.99));
  }
  if (hangs > 0) {
    std::printf("%-34s %6d %14.1f %14.1f %14.1f %14.1f\n",
                fmt::format("SIGSTOP (hang){}", label).c_str(), hangs,
                percentile(r.hung.detect_ms, 0.5), percentile(r.hung.detect_ms, 0.99),
                percentile(r.hung.resume_ms, 0.5), percentile(r.hung.resume_ms, 0.99));
  }
  if (registry_kills > 0) {
    std::printf("%-34s %6d %14s %14s %14.1f %14.1f  (p50, max; target <= 2000 ms)\n",
                fmt::format("registry kill -9{}", label).c_str(), registry_kills, "-", "-",
                percentile(r.registry_back_ms, 0.5), percentile(r.registry_back_ms, 1.0));
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench restart: failure detection, restart and boot times of the registry"};
  int kills = 50, hangs = 10, rounds = 1, registry_kills = 0;
  bool json = false, security = false;
  app.add_option("--kills", kills, "kill -9 failures to time (0: none)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--hangs", hangs, "SIGSTOP hangs to time (0: none)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--registry-kills", registry_kills,
                 "kill -9 the registry this often and time until every module runs again under "
                 "the new one (0: never; beyond 5, boot's limit of 5 restarts a minute paces them)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--security", security,
               "also with DDS Security (a keystore made here), alternated with the plain runs");
  app.add_option("--rounds", rounds,
                 "rounds (each: the failures split over the rounds, and one boot of 20 modules "
                 "per kind)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--json", json, "print JSON (one line per kind)");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    const int domain = 1 + getpid() % 200;
    const bool netns = oscar::test::TestHosts::unavailable().empty();
    const int hosts = netns ? 3 : 1;
    Run plain, secured;
    // Plain and secured alternate round by round, so both see the same machine.
    for (int round = 0; round < rounds; ++round) {
      const int k = kills / rounds + (round < kills % rounds ? 1 : 0);
      const int h = hangs / rounds + (round < hangs % rounds ? 1 : 0);
      const int r = registry_kills / rounds + (round < registry_kills % rounds ? 1 : 0);
      for (const bool with_keys : {false, true}) {
        if (with_keys && !security) continue;
        auto& run = with_keys ? secured : plain;
        if (k > 0 || r > 0) time_failures(run, k, h, r, domain, with_keys);
        run.boot20_ms.push_back(boot_time_ms(20, netns, domain, with_keys));
        std::fprintf(stderr, "round %d/%d%s: boot of 20 modules %.0f ms\n", round + 1, rounds,
                     with_keys ? " (secured)" : "", run.boot20_ms.back());
      }
    }
    if (json) {
      print_json("none", plain, kills, hangs, registry_kills, hosts);
      if (security) print_json("keystore", secured, kills, hangs, registry_kills, hosts);
      return 0;
    }
    std::printf("oscar bench restart: lease 300 ms, restart backoff 200 ms (the defaults)\n\n");
    std::printf("%-34s %6s %14s %14s %14s %14s\n", "failure", "count", "detect p50 ms",
                "detect p99 ms", "running p50 ms", "running p99 ms");
    print_rows("", plain, kills, hangs, registry_kills);
    if (security) print_rows(", secured", secured, kills, hangs, registry_kills);
    const auto where =
        netns ? "3 test hosts (network namespaces)" : "1 host (no root: no test hosts)";
    std::printf("\nboot of 20 modules on %s, median of %d: %.0f ms to running\n", where, rounds,
                percentile(plain.boot20_ms, 0.5));
    if (security) {
      const double b = percentile(secured.boot20_ms, 0.5);
      std::printf(
          "  secured: %.0f ms (%.2f x); restart p99 secured/plain: %.2f x\n", b,
          b / percentile(plain.boot20_ms, 0.5),
          percentile(secured.crashes.resume_ms, 0.99) / percentile(plain.crashes.resume_ms, 0.99));
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench restart: %s\n", e.what());
    return 2;
  }
}
