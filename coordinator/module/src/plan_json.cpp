#include "oscar/coordinator/plan_json.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

namespace oscar::coordinator {

std::string plan_json(const AppletPlan& plan) {
  nlohmann::ordered_json services = nlohmann::ordered_json::object();
  for (const auto& s : plan.services()) {
    nlohmann::ordered_json entry;
    entry["holders"] = s.holders();
    entry["access"] = s.access();
    entry["waiting"] = s.waiting();
    if (!s.available()) entry["available"] = false;
    services[s.name()] = std::move(entry);
  }
  nlohmann::ordered_json applets = nlohmann::ordered_json::array();
  for (const auto& a : plan.applets()) {
    applets.push_back({{"name", a.name()}, {"process", a.process()}, {"state", a.state()}});
  }
  nlohmann::ordered_json out;
  out["services"] = std::move(services);
  out["applets"] = std::move(applets);
  return out.dump();
}

std::string plan_table(const AppletPlan& plan) {
  std::string out =
      fmt::format("{:<20} {:<10} {:<24} {}\n", "SERVICE", "ACCESS", "HOLDERS", "WAITING");
  for (const auto& s : plan.services()) {
    const auto holders = s.available() ? fmt::format("{}", fmt::join(s.holders(), ","))
                                       : std::string("(unavailable)");
    out += fmt::format("{:<20} {:<10} {:<24} {}\n", s.name(), s.access(),
                       holders.empty() ? "-" : holders,
                       s.waiting().empty() ? "-" : fmt::format("{}", fmt::join(s.waiting(), ",")));
  }
  out += fmt::format("\n{:<20} {:<14} {}\n", "APPLET", "PROCESS", "STATE");
  for (const auto& a : plan.applets()) {
    out += fmt::format("{:<20} {:<14} {}\n", a.name(), a.process(), a.state());
  }
  return out;
}

}  // namespace oscar::coordinator
