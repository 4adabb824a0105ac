// oscar ps: the modules of the running system — host, pid, mode, state, restarts, cue rates,
// and whether one runs under a debugger.
#include <cstdio>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>

#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"
#include "oscar/time.hpp"

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
    oscar::RegistryClient client(*participant, "ps");
    const auto s = client.wait_for([](const oscar::SystemState&) { return true; },
                                   std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)));
    if (!s) {
      std::fprintf(stderr, "oscar ps: no registry answered on domain %d within %.1f s%s\n",
                   participant->domain(), timeout_s,
                   oscar::where_systems_run(participant->domain()).c_str());
      return 1;
    }
    if (json) {
      std::printf("%s\n", to_json(*s).dump().c_str());
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
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar ps: %s\n", e.what());
    return 2;
  }
}
