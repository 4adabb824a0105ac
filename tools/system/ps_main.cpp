// oscar ps: the modules of the running system — host, pid, mode, state, restarts, cue rates,
// whether one runs under a debugger, and how far each host's clock is from the registry's.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>

#include "oscar/registry/clock_topics.hpp"
#include "oscar/registry/log_printer.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"

namespace {

std::string modes(const oscar::ModuleState& s) {
  std::string out;
  for (const auto& k : s.kernels()) {
    if (!out.empty()) out += ",";
    out += k.mode() == "continuous"
               ? "cont(" + oscar::format_duration(std::chrono::nanoseconds(k.cycle_ns())) + ")"
               : k.mode();
    if (k.stub()) out += "+stub";
  }
  return out.empty() ? "-" : out;
}

// Each host's latest clock estimate (docs/boot.md, "Clocks"), as its monitor publishes it.
class HostClocks {
 public:
  explicit HostClocks(oscar::DdsParticipant& participant)
      : reader_(participant, oscar::topics::host_clocks(),
                [this](const oscar::HostClock& c, const auto&) {
                  std::lock_guard lock(mutex_);
                  latest_[c.host()] = c;
                }) {}
  /// Waits up to `timeout` until every host of `s` has an estimate (both are kept for late
  /// readers, but a monitor's writer may be discovered after the registry's).
  std::map<std::string, oscar::HostClock> wait_for_hosts_of(const oscar::SystemState& s,
                                                            std::chrono::milliseconds timeout) {
    std::set<std::string> hosts;
    for (const auto& m : s.modules()) hosts.insert(m.host());
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (true) {
      {
        std::lock_guard lock(mutex_);
        const bool all = std::all_of(hosts.begin(), hosts.end(),
                                     [&](const auto& h) { return latest_.count(h) != 0; });
        if (all || std::chrono::steady_clock::now() >= until) return latest_;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

 private:
  std::mutex mutex_;
  std::map<std::string, oscar::HostClock> latest_;
  oscar::TopicReader<oscar::HostClock, oscar::HostClockPubSubType> reader_;
};

double ms(long long ns) { return static_cast<double>(ns) / 1e6; }

void print_clocks(const oscar::SystemState& s,
                  const std::map<std::string, oscar::HostClock>& clocks) {
  std::printf("\n%-10s %s\n", "HOST", "CLOCK (vs the registry's)");
  std::set<std::string> without;
  for (const auto& m : s.modules()) {
    if (clocks.count(m.host()) == 0) without.insert(m.host());
  }
  for (const auto& host : without) {
    std::printf("%-10s no estimate (yet)\n", host.c_str());
  }
  for (const auto& [host, c] : clocks) {
    const bool off = std::abs(c.offset_ns()) >
                     std::chrono::nanoseconds(oscar::LogPrinter::kClockWarning).count();
    std::printf("%-10s %+9.3f ms ± %.3f ms  (%u samples)%s\n", host.c_str(), ms(c.offset_ns()),
                ms(c.uncertainty_ns()), c.samples(),
                off ? "  ! over 10 ms: sync the hosts (chrony, PTP)" : "");
  }
}

nlohmann::json to_json(const std::map<std::string, oscar::HostClock>& clocks) {
  auto j = nlohmann::json::array();
  for (const auto& [host, c] : clocks) {
    j.push_back({{"host", host},
                 {"offset_ns", c.offset_ns()},
                 {"uncertainty_ns", c.uncertainty_ns()},
                 {"samples", c.samples()}});
  }
  return j;
}

nlohmann::json to_json(const oscar::SystemState& s) {
  auto j = nlohmann::json{{"system", s.system()},
                          {"state", s.state()},
                          {"message", s.message()},
                          {"hosts_lost", s.hosts_lost()},
                          {"modules", nlohmann::json::array()}};
  for (const auto& m : s.modules()) {
    nlohmann::json kernels = nlohmann::json::array();
    for (const auto& k : m.state().kernels()) {
      nlohmann::json commands = nlohmann::json::array();
      for (const auto& c : k.commands())
        commands.push_back({{"name", c.name()}, {"type", c.type()}});
      kernels.push_back({{"name", k.name()},
                         {"type", k.type()},
                         {"mode", k.mode()},
                         {"cycle_ns", k.cycle_ns()},
                         {"stub", k.stub()},
                         {"params", k.params()},
                         {"inputs", k.inputs()},
                         {"commands", commands},
                         {"published", k.published()},
                         {"failures", k.failures()},
                         {"last_failure", k.last_failure()},
                         {"cycles", k.cycles()}});
    }
    j["modules"].push_back({{"name", m.name()},
                            {"host", m.host()},
                            {"pid", m.pid()},
                            {"incarnation", m.incarnation()},
                            {"status", m.status()},
                            {"restarts", m.restarts()},
                            {"last_failure", m.last_failure()},
                            {"cues_per_s", m.cues_per_s()},
                            {"debug", m.debug()},
                            {"suspended", m.state().suspended()},
                            {"kernels", kernels}});
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar ps: the modules of the running system"};
  oscar::SystemOptions tool;
  double timeout_s = 3;
  bool json = false;
  tool.add_to(app);
  app.add_option("--timeout", timeout_s, "seconds to wait for the registry");
  app.add_flag("--json", json, "print the system state as JSON");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    auto participant = tool.participant("oscar-ps");
    HostClocks host_clocks(*participant);
    oscar::RegistryClient client(*participant, "ps");
    const std::chrono::milliseconds wait(static_cast<long>(timeout_s * 1000));
    const auto s = client.current_state(wait);
    if (!s) {
      fmt::print(stderr, "oscar ps: {}\n",
                 oscar::why_no_state(client, participant->domain(), wait));
      return 1;
    }
    // The monitors' writers may be discovered a little after the registry's.
    const auto clocks = host_clocks.wait_for_hosts_of(
        *s, std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)));
    if (json) {
      auto j = to_json(*s);
      j["clocks"] = to_json(clocks);
      std::printf("%s\n", j.dump().c_str());
      return 0;
    }
    std::printf("system %s: %s (%s)\n", s->system().c_str(), s->state().c_str(),
                s->message().c_str());
    std::printf("%-16s %-10s %-8s %-4s %-11s %-8s %9s  %s\n", "MODULE", "HOST", "PID", "INC",
                "STATE", "RESTARTS", "CUES/S", "MODES");
    for (const auto& m : s->modules()) {
      std::printf(
          "%-16s %-10s %-8d %-4u %-11s %-8u %9.1f  %s%s%s\n", m.name().c_str(), m.host().c_str(),
          m.pid(), m.incarnation(),
          (m.state().suspended() && m.status() == "running" ? "suspended" : m.status().c_str()),
          m.restarts(), m.cues_per_s(), modes(m.state()).c_str(),
          m.debug().empty() ? "" : ("  debug: " + m.debug()).c_str(),
          m.last_failure().empty() ? "" : ("  last failure: " + m.last_failure()).c_str());
      for (const auto& k : m.state().kernels()) {
        if (k.failures() == 0) continue;
        std::printf("  kernel %s: %llu failures, last in %s\n", k.name().c_str(),
                    static_cast<unsigned long long>(k.failures()), k.last_failure().c_str());
      }
    }
    print_clocks(*s, clocks);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar ps: %s\n", e.what());
    return 2;
  }
}
