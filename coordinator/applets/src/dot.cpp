#include "oscar/applets/dot.hpp"

#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <utility>

namespace oscar::applets {

std::string dot_quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

namespace {

std::string priority_name(int p) {
  switch (p) {
    case kPriorityLow:
      return "low";
    case kPriorityNormal:
      return "normal";
    case kPriorityHigh:
      return "high";
    case kPrioritySystem:
      return "system";
    default:
      return std::to_string(p);
  }
}

// What the colours and edges mean, in a box of its own.
std::string legend() {
  std::string out =
      "  subgraph cluster_legend {\n    label=\"legend\";\n    fontname=\"Helvetica\";\n"
      "    node [shape=box, style=filled, fontsize=10];\n";
  const std::pair<const char*, const char*> bundles[] = {
      {"active", "palegreen"},
      {"granted, waiting for hand-over", "khaki"},
      {"blocked", "lightgrey"},
      {"being revoked", "orange"},
      {"idle", "white"}};
  std::string previous;
  for (const auto& [state, colour] : bundles) {
    const auto id = dot_quote(std::string("legend:") + state);
    out += "    " + id + " [fillcolor=" + colour +
           ", label=" + dot_quote(std::string("bundle ") + state) + "];\n";
    if (!previous.empty()) out += "    " + previous + " -> " + id + " [style=invis];\n";
    previous = id;
  }
  out += "    \"legend:service\" [shape=ellipse, fillcolor=lightblue, label=\"service in use\"];\n";
  const std::pair<const char*, const char*> edges[] = {
      {"exclusive, granted", "color=red"},
      {"shared, granted", "color=blue"},
      {"requested, not granted", "color=grey"},
      {"provides (from a service applet)", "color=darkgreen, dir=back"},
      {"needs (a service's dependency)", "style=dashed"}};
  for (const auto& [meaning, colour] : edges) {
    const auto from = dot_quote(std::string("legend:from ") + meaning);
    out += "    " + from + " [shape=point, width=0.05];\n    " + from + " -> \"legend:service\" [" +
           colour + ", label=" + dot_quote(meaning) + ", fontsize=10];\n";
  }
  return out + "  }\n";
}

}  // namespace

std::string to_dot(const Scheduler& s) {
  const Model& m = s.model();
  const Plan& plan = s.plan();
  std::string out = "digraph applets {\n  rankdir=LR;\n  node [fontname=\"Helvetica\"];\n";
  for (ServiceId id = 0; id < m.services().size(); ++id) {
    const Service& svc = m.service(id);
    out += "  " + dot_quote("s:" + svc.name) + " [shape=ellipse, style=filled, fillcolor=" +
           (plan.uses[id].empty() ? "white" : "lightblue") + ", label=" +
           dot_quote(svc.name + (svc.exclusive_only ? "\n(exclusive only)" : "") + "\n" +
                     s.holder(id)) +
           "];\n";
    for (const Dependency& d : svc.dependencies) {
      out += "  " + dot_quote("s:" + svc.name) + " -> " +
             dot_quote("s:" + m.service(d.service).name) +
             " [style=dashed, label=" + dot_quote("needs " + std::string(to_string(d.access))) +
             "];\n";
    }
  }
  for (AppletId a = 0; a < m.applets().size(); ++a) {
    const Applet& ap = m.applet(a);
    out += "  subgraph " + dot_quote("cluster_" + ap.name) + " {\n    label=" +
           dot_quote(ap.name + (ap.provides.empty() ? "" : " (service applet)")) + ";\n";
    for (BundleId b : ap.bundles) {
      const Bundle& bundle = m.bundle(b);
      // A bundle given back is still in use until its reassigners' first wait limit (Abb. 4.13);
      // a service applet's bundle may be active through inheritance without a request.
      const auto revoke_by = s.revoke_deadline(b);
      const std::string state =
          revoke_by         ? "being revoked, until " + std::to_string(revoke_by->count()) + " ms"
          : s.active(b)     ? "active"
          : !s.requested(b) ? "idle"
          : plan.bundle_granted[b] ? "granted, waiting for hand-over"
          : s.deadline(b) && s.deadline(b)->t_early > plan.time
              ? "blocked until t_early " + std::to_string(s.deadline(b)->t_early.count()) + " ms"
              : "blocked";
      const std::string colour = revoke_by                        ? "orange"
                                 : state == "idle"                ? "white"
                                 : state == "active"              ? "palegreen"
                                 : state.rfind("blocked", 0) == 0 ? "lightgrey"
                                                                  : "khaki";
      out += "    " + dot_quote("b:" + ap.name + "/" + bundle.name) +
             " [shape=box, style=filled, " + "fillcolor=" + colour + ", label=" +
             dot_quote(bundle.name + "\nprio " + priority_name(s.priority(b)) + "\n" + state) +
             "];\n";
    }
    // A service applet's services start at its first bundle; one without bundles (its services
    // need nothing) gets a node of its own, so no edge points at a bundle that is not drawn.
    std::string provider =
        ap.bundles.empty() ? "a:" + ap.name : "b:" + ap.name + "/" + m.bundle(ap.bundles[0]).name;
    if (ap.bundles.empty() && !ap.provides.empty()) {
      out += "    " + dot_quote(provider) +
             " [shape=box, style=dashed, label=" + dot_quote(ap.name + "\nno bundles") + "];\n";
    }
    out += "  }\n";
    for (ServiceId p : ap.provides) {
      out += "  " + dot_quote(provider) + " -> " + dot_quote("s:" + m.service(p).name) +
             " [dir=back, color=darkgreen, label=provides];\n";
    }
    for (BundleId b : ap.bundles) {
      for (ResourceId r : m.bundle(b).resources) {
        const Resource& res = m.resource(r);
        const bool exclusive = res.access == Access::kExclusive;
        out += "  " + dot_quote("b:" + ap.name + "/" + m.bundle(b).name) + " -> " +
               dot_quote("s:" + m.service(res.service).name) +
               " [color=" + (plan.resource_granted[r] ? (exclusive ? "red" : "blue") : "grey") +
               ", label=" + dot_quote(std::string(to_string(res.access))) + "];\n";
      }
    }
  }
  return out + legend() + "}\n";
}

bool write_picture(const Scheduler& s, const std::string& path) {
  return write_picture(to_dot(s), path);
}

bool write_picture(const std::string& dot, const std::string& path) {
  const bool svg = path.size() > 4 && path.substr(path.size() - 4) == ".svg";
  const std::string dot_path = svg ? path + ".dot" : path;
  {
    std::ofstream out(dot_path);
    if (!out) throw std::invalid_argument(dot_path + ": cannot write the picture");
    out << dot;
  }
  if (!svg) return true;
  if (std::system("command -v dot >/dev/null 2>&1") != 0) return false;
  const std::string cmd = "dot -Tsvg '" + dot_path + "' -o '" + path + "'";
  return std::system(cmd.c_str()) == 0;
}

}  // namespace oscar::applets
