// oscar-boot (`oscar boot SYSTEM.yaml`): checks a system file, starts the registry and one
// monitor per host, waits until every module is announced, follows the merged log until
// Ctrl-C (or --duration), then shuts the system down in order and leaves no process behind.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <oscar/configPubSubTypes.h>
#include <CLI/CLI.hpp>

#include "oscar/cue_types.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/process_util.hpp"
#include "oscar/registry/launch_command.hpp"
#include "oscar/registry/log_printer.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/supervisor.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"

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

std::string summary(const oscar::SystemState& s) {
  std::vector<std::string> parts;
  for (const auto& m : s.modules()) {
    if (m.status() != "running") parts.push_back(m.name() + " " + m.status());
  }
  return parts.empty() ? std::string() : " [" + fmt::format("{}", fmt::join(parts, ", ")) + "]";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar boot: boots a system of modules across hosts from one YAML file"};
  std::string file, log_dir;
  int domain = -1;
  double timeout_s = 30, duration_s = 0;
  bool check = false;
  app.add_option("system", file, "the system file (DESIGN §7; docs/boot.md)")->required();
  app.add_option("-d,--domain", domain, "DDS domain (default: the file's)");
  app.add_option("--timeout", timeout_s, "seconds to wait until every module is announced");
  app.add_option("--duration", duration_s, "stop after this many seconds (default: Ctrl-C)");
  app.add_option("--log-dir", log_dir, "where process output goes (default /tmp/oscar/...)");
  app.add_flag("--check", check, "check the system file and its modules, start nothing");
  CLI11_PARSE(app, argc, argv);

  const auto signals = oscar::block_stop_signals();

  oscar::LogPrinter log(stdout, isatty(1) != 0);
  try {
    auto system = oscar::SystemSpec::load(file);
    if (domain >= 0) system.override_domain(domain);
    oscar::register_standard_cue_types();
    system.check_modules(oscar::plugin_search_path());
    const auto& local = system.local_host();
    check_hosts(system);
    if (check) {
      std::printf("%s: system '%s', %zu modules on %zu hosts: ok\n", file.c_str(),
                  system.name.c_str(), system.modules.size(), system.hosts.size());
      return 0;
    }
    if (log_dir.empty()) log_dir = fmt::format("/tmp/oscar/{}-{}", system.name, system.domain);
    // A new boot numbers cues from 1 again; only restarts within it continue the numbering.
    std::error_code ec;
    for (const auto& e : std::filesystem::recursive_directory_iterator(log_dir, ec)) {
      if (e.path().extension() == ".seq") std::filesystem::remove(e.path(), ec);
    }
    const auto started = Clock::now();
    log.note("boot", fmt::format("booting '{}' from {}: {} modules on {} hosts, domain {}, logs "
                                 "in {}",
                                 system.name, file, system.modules.size(), system.hosts.size(),
                                 system.domain, log_dir));
    oscar::DdsParticipant participant(system.domain, "oscar-boot",
                                      oscar::NetworkConfig::for_host(system.root, local.name));
    std::mutex last_line_mutex;  // DDS may call back from its UDP and shared-memory threads
    std::string last_line;
    oscar::RegistryClient registry(participant, "boot", [&](const oscar::SystemState& s) {
      auto line = fmt::format("system {}: {}{}", s.state(), s.message(), summary(s));
      std::lock_guard lock(last_line_mutex);
      if (line != last_line) {
        log.note("registry", line, s.state() == "suspended" ? oscar::LOG_WARN : oscar::LOG_INFO);
        last_line = std::move(line);
      }
    });
    oscar::TopicReader<oscar::LogRecord, oscar::LogRecordPubSubType> logs(
        participant, "oscar/log", oscar::qos::stream_reader(100),
        [&](const oscar::LogRecord& r, const auto&) { log.add(r); });

    // Registry first (it waits for the monitors), then one monitor per host.
    oscar::Supervisor children(log_dir);
    const auto dom = std::to_string(system.domain);
    children.start("registry", 1,
                   {oscar::sibling_program("oscar-registry"), "--system", file, "--host",
                    local.name, "--domain", dom});
    for (const auto& h : system.hosts) {
      children.start(
          "monitor-" + h.name, 1,
          oscar::on_host(h, {oscar::sibling_program("oscar-monitor"), "--system", file, "--host",
                             h.name, "--domain", dom, "--log-dir", log_dir + "/" + h.name}));
    }
    const auto running =
        registry.wait_for([](const oscar::SystemState& s) { return s.state() == "running"; },
                          std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)));
    int code = 0;
    if (!running) {
      const auto last = registry.latest();
      log.note("boot",
               fmt::format("not every module was announced within {} s: {} (their output is in "
                           "{})",
                           timeout_s, last ? last->message() : "no registry answered", log_dir),
               oscar::LOG_ERROR);
      code = 1;
    } else {
      log.note(
          "boot",
          fmt::format("system '{}' running after {} ms (Ctrl-C stops it)", system.name,
                      std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - started)
                          .count()));
      const auto until =
          duration_s > 0
              ? Clock::now() + std::chrono::milliseconds(static_cast<long>(duration_s * 1000))
              : Clock::time_point::max();
      while (Clock::now() < until &&
             !oscar::wait_for_stop(signals, std::chrono::milliseconds(50))) {
        log.flush();
      }
    }
    log.note("boot", "shutting down");
    try {
      registry.request(oscar::REG_SHUTDOWN, "", std::chrono::milliseconds(3000));
      registry.wait_for([](const oscar::SystemState& s) { return s.state() == "stopped"; },
                        std::chrono::seconds(20));
    } catch (const std::exception& e) {
      log.note("boot", std::string("registry: ") + e.what(), oscar::LOG_WARN);
    }
    // Monitors exit when the registry tells them; what is left is stopped here.
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
