// oscar bench restart: how fast the registry notices a failure and has the system running
// again (issue 3), and how long booting 20 modules on 3 test hosts takes. Prints a table, or
// JSON with --json. Never decides pass/fail by time: it reports what it measured.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/process_util.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/time.hpp"
#include "percentile.hpp"  // tests/common
#include "process.hpp"     // tests/common
#include "test_hosts.hpp"  // tests/netns

namespace {
using namespace std::chrono_literals;

using oscar::test::percentile;

const oscar::ModuleEntry* find(const oscar::SystemState& s, const std::string& name) {
  for (const auto& m : s.modules()) {
    if (m.name() == name) return &m;
  }
  return nullptr;
}

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
    const auto incarnation = find(*before, name)->incarnation();
    const auto t0 = oscar::wall_now();
    kill(static_cast<pid_t>(find(*before, name)->pid()), sig);
    const auto detected = registry.wait_for(
        [&](const oscar::SystemState& s) { return find(s, name)->status() != "running"; }, 30s);
    const auto back = registry.wait_for(
        [&](const oscar::SystemState& s) {
          return s.state() == "running" && find(s, name)->incarnation() > incarnation;
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

// Boots `modules` sources/sinks over `hosts` test hosts (or this host) and returns what
// oscar boot reports as its time to `running`.
double boot_time_ms(int modules, bool netns, int domain) {
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
  std::vector<std::string> argv;
  if (netns) argv = hosts->on(1);
  argv.insert(argv.end(),
              {oscar::sibling_program("oscar-boot"), file, "--domain", std::to_string(domain),
               "--log-dir", oscar::test::temp_path("bench_boot20_logs"), "--duration", "1"});
  oscar::test::Process boot(argv, oscar::test::temp_path("bench_boot20") + ".log");
  if (boot.wait(120s) != 0)
    throw std::runtime_error("boot of 20 modules failed:\n" + boot.output());
  std::smatch m;
  const auto out = boot.output();
  if (!std::regex_search(out, m, std::regex("running after ([0-9]+) ms"))) {
    throw std::runtime_error("boot did not report its time:\n" + out);
  }
  return std::stod(m[1]);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench restart: failure detection, restart and boot times of the registry"};
  int kills = 50, hangs = 10;
  bool json = false;
  app.add_option("--kills", kills, "kill -9 failures to time")->check(CLI::PositiveNumber);
  app.add_option("--hangs", hangs, "SIGSTOP hangs to time (0: none)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--json", json, "print JSON");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    const int domain = 1 + getpid() % 200;
    const auto file = oscar::test::temp_path("bench_restart") + ".yaml";
    std::ofstream(file) << R"(system: bench_restart
lease: 300ms
modules:
  - { name: a, kernels: [ { type: bench_source, name: a, params: { type: Bool } } ], mode: { continuous: 10ms }, restart: { max: 100000 } }
  - { name: b, kernels: [ { type: relay, name: b, params: { type: Bool }, inputs: { in: a/out } } ], mode: single_step, restart: { max: 100000 } }
  - { name: c, kernels: [ { type: bench_sink, name: c, params: { type: Bool }, inputs: { in: b/out } } ], mode: single_step, restart: { max: 100000 } }
)";
    oscar::test::Process boot(
        {oscar::sibling_program("oscar-boot"), file, "--domain", std::to_string(domain),
         "--log-dir", oscar::test::temp_path("bench_restart_logs")},
        oscar::test::temp_path("bench_restart") + ".log");
    oscar::DdsParticipant participant(domain, "bench-restart");
    oscar::RegistryClient registry(participant, "bench");
    const auto crashes = fail_modules(registry, {"a", "b", "c"}, kills, SIGKILL);
    const auto hung =
        hangs > 0 ? fail_modules(registry, {"a", "b", "c"}, hangs, SIGSTOP) : Failures{};
    kill(boot.pid(), SIGINT);
    boot.wait(60s);

    const bool netns = oscar::test::TestHosts::unavailable().empty();
    const double boot20 = boot_time_ms(20, netns, domain);
    if (json) {
      std::printf(
          "{\"kills\":%d,\"detect_ms_p50\":%.1f,\"detect_ms_p99\":%.1f,\"resume_ms_p50\":%.1f,"
          "\"resume_ms_p99\":%.1f,\"hangs\":%d,\"hang_detect_ms_p50\":%.1f,"
          "\"hang_detect_ms_p99\":%.1f,\"hang_resume_ms_p50\":%.1f,\"hang_resume_ms_p99\":%.1f,"
          "\"boot20_ms\":%.0f,\"boot20_hosts\":%d,\"lease_ms\":300,\"backoff_ms\":200}\n",
          kills, percentile(crashes.detect_ms, 0.5), percentile(crashes.detect_ms, 0.99),
          percentile(crashes.resume_ms, 0.5), percentile(crashes.resume_ms, 0.99), hangs,
          percentile(hung.detect_ms, 0.5), percentile(hung.detect_ms, 0.99),
          percentile(hung.resume_ms, 0.5), percentile(hung.resume_ms, 0.99), boot20, netns ? 3 : 1);
      return 0;
    }
    std::printf("oscar bench restart: lease 300 ms, restart backoff 200 ms (the defaults)\n\n");
    std::printf("%-22s %6s %14s %14s %14s %14s\n", "failure", "count", "detect p50 ms",
                "detect p99 ms", "running p50 ms", "running p99 ms");
    std::printf("%-22s %6d %14.1f %14.1f %14.1f %14.1f\n", "kill -9 (crash)", kills,
                percentile(crashes.detect_ms, 0.5), percentile(crashes.detect_ms, 0.99),
                percentile(crashes.resume_ms, 0.5), percentile(crashes.resume_ms, 0.99));
    if (hangs > 0) {
      std::printf("%-22s %6d %14.1f %14.1f %14.1f %14.1f\n", "SIGSTOP (hang)", hangs,
                  percentile(hung.detect_ms, 0.5), percentile(hung.detect_ms, 0.99),
                  percentile(hung.resume_ms, 0.5), percentile(hung.resume_ms, 0.99));
    }
    std::printf("\nboot of 20 modules on %d %s: %.0f ms to running\n", netns ? 3 : 1,
                netns ? "test hosts (network namespaces)" : "host (no root: no test hosts)",
                boot20);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench restart: %s\n", e.what());
    return 2;
  }
}
