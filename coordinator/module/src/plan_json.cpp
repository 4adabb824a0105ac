#include "oscar/coordinator/plan_json.hpp"

#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "oscar/applets/dot.hpp"

namespace oscar::coordinator {

std::string plan_json(const AppletPlan& plan) {
  nlohmann::ordered_json services = nlohmann::ordered_json::object();
  for (const auto& s : plan.services()) {
    nlohmann::ordered_json entry;
    entry["holders"] = s.holders();
    entry["access"] = s.access();
    entry["waiting"] = s.waiting();
    entry["plan"] = s.plan();
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

namespace {

const char* state_colour(const std::string& state) {
  if (state == "holding") return "palegreen";
  if (state == "waiting") return "khaki";
  if (state == "crashed") return "salmon";
  if (state == "absent") return "lightgrey";
  return "white";
}

}  // namespace

std::string plan_dot(const AppletPlan& plan) {
  std::string out =
      "digraph plan {\n  rankdir=LR;\n  fontname=\"Helvetica\";\n"
      "  node [fontname=\"Helvetica\", fontsize=11];\n"
      "  edge [fontname=\"Helvetica\", fontsize=9];\n";
  out += fmt::format("  label={};\n  labelloc=t;\n",
                     applets::dot_quote(fmt::format("{}: the coordinator's plan ({} plans so far)",
                                                    plan.system(), plan.plans())));
  for (const auto& a : plan.applets()) {
    out += fmt::format("  {} [shape=box, style=filled, fillcolor={}, label={}];\n",
                       applets::dot_quote("a:" + a.name()), state_colour(a.state()),
                       applets::dot_quote(a.name() + "\n" + a.state() + " in " + a.process()));
  }
  std::set<std::string> modules;
  for (const auto& s : plan.services()) {
    const char* fill = !s.available() ? "lightgrey" : !s.holders().empty() ? "lightblue" : "white";
    out += fmt::format(
        "  {} [shape=ellipse, style=filled, fillcolor={}, label={}];\n",
        applets::dot_quote("s:" + s.name()), fill,
        applets::dot_quote(s.name() + "\n" + s.access() + (s.available() ? "" : ", unavailable") +
                           "\nplan: " + s.plan()));
    for (const auto& h : s.holders()) {
      out += fmt::format("  {} -> {} [color=darkgreen, penwidth=2, label=holds];\n",
                         applets::dot_quote("a:" + h), applets::dot_quote("s:" + s.name()));
    }
    for (const auto& w : s.waiting()) {
      out += fmt::format("  {} -> {} [color=grey, style=dashed, label=waits];\n",
                         applets::dot_quote("a:" + w), applets::dot_quote("s:" + s.name()));
    }
    for (const auto& n : s.needs()) {
      out += fmt::format("  {} -> {} [style=bold, label=needs];\n",
                         applets::dot_quote("s:" + s.name()), applets::dot_quote("s:" + n));
    }
    for (const auto& p : s.providers()) {
      if (p.starts_with("applet:")) {
        out += fmt::format("  {} -> {} [dir=back, color=blue, label=provides];\n",
                           applets::dot_quote("s:" + s.name()),
                           applets::dot_quote("a:" + p.substr(7)));
        continue;
      }
      if (modules.insert(p).second) {
        out += fmt::format("  {} [shape=component, label={}];\n", applets::dot_quote("m:" + p),
                           applets::dot_quote(p));
      }
      out += fmt::format("  {} -> {} [style=dotted, arrowhead=none, label=\"provided by\"];\n",
                         applets::dot_quote("s:" + s.name()), applets::dot_quote("m:" + p));
    }
  }
  out +=
      "  subgraph cluster_legend {\n    label=\"legend\";\n"
      "    node [shape=box, style=filled, fontsize=9];\n";
  for (const char* state : {"holding", "waiting", "idle", "crashed", "absent"}) {
    out += fmt::format("    {} [fillcolor={}, label={}];\n",
                       applets::dot_quote(std::string("legend:") + state), state_colour(state),
                       applets::dot_quote(std::string("applet ") + state));
  }
  out +=
      "    \"legend:service\" [shape=ellipse, fillcolor=lightblue, label=\"service held\"];\n"
      "    \"legend:module\" [shape=component, style=solid, label=\"provider module\"];\n"
      "  }\n}\n";
  return out;
}

}  // namespace oscar::coordinator
