// oscar graph: the running system as a Graphviz graph — modules (clusters with host, pid and
// state), kernels (type, mode, stub), channels (with their cue type from discovery) and the
// wiring between them — from the registry's oscar/system/state; rendered with `dot`.
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>

#include <oscar/command_line.hpp>

#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"
#include "oscar/time.hpp"
#include "oscar/topics.hpp"

namespace {

// A DOT string; "\n" in `s` stays a DOT line break.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string colour(const std::string& status) {
  if (status == "running") return "palegreen";
  if (status == "failed" || status == "lost") return "salmon";
  if (status == "suspended" || status == "restarting") return "khaki";
  return "lightgrey";
}

// DOT for the system: channel "k/ch" nodes between producer and consumer kernels.
std::string to_dot(const oscar::SystemState& s,
                   const std::map<std::string, oscar::DdsParticipant::DiscoveredWriter>& writers) {
  std::string dot =
      fmt::format("digraph {} {{\n  label={};\n  rankdir=LR;\n  node [fontname=\"sans\"];\n",
                  quoted(s.system()), quoted(s.system() + " (" + s.state() + ")"));
  std::set<std::string> kernels, channels;
  std::string edges;
  for (const auto& m : s.modules()) {
    dot += fmt::format("  subgraph {} {{\n    label={};\n    style=filled; fillcolor={};\n",
                       quoted("cluster_" + m.name()),
                       quoted(fmt::format("{} @{} pid {} [{}{}]", m.name(), m.host(), m.pid(),
                                          m.status(), m.state().suspended() ? ", suspended" : "")),
                       colour(m.status()));
    for (const auto& k : m.state().kernels()) {
      kernels.insert(k.name());
      const auto mode =
          k.mode() == "continuous"
              ? "continuous " + oscar::format_duration(std::chrono::nanoseconds(k.cycle_ns()))
              : k.mode();
      dot += fmt::format("    {} [shape=box, style=filled, fillcolor=white, label={}];\n",
                         quoted("k:" + k.name()),
                         quoted(fmt::format("{}\\n({})\\n{}{}", k.name(), k.type(), mode,
                                            k.stub() ? " +stub" : "")));
      for (const auto& wire : k.inputs()) {  // "input=kernel/channel"
        const auto eq = wire.find('=');
        if (eq == std::string::npos) continue;
        const auto source = wire.substr(eq + 1);
        channels.insert(source);
        edges += fmt::format("  {} -> {} [label={}];\n", quoted("c:" + source),
                             quoted("k:" + k.name()), quoted(wire.substr(0, eq)));
      }
    }
    dot += "  }\n";
  }
  // Channels nobody consumes still show, from discovery.
  for (const auto& [topic, w] : writers) {
    if (!oscar::topics::is_cue(topic)) continue;
    const auto source = topic.substr(oscar::topics::kCuePrefix.size());
    if (kernels.count(source.substr(0, source.find('/')))) channels.insert(source);
  }
  for (const auto& c : channels) {
    const auto w = writers.find(oscar::topics::cue(c));
    const auto type = w == writers.end() ? std::string("?") : w->second.type;
    dot += fmt::format("  {} [shape=ellipse, label={}];\n", quoted("c:" + c),
                       quoted(c + "\\n" + type));  // "kernel/channel": many are named "out"
    const auto producer = c.substr(0, c.find('/'));
    if (kernels.count(producer)) {
      dot += fmt::format("  {} -> {};\n", quoted("k:" + producer), quoted("c:" + c));
    }
  }
  return dot + edges + "}\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar graph: the running system as a graph (DOT, or SVG rendered with dot)"};
  oscar::SystemOptions tool;
  tool.add_to(app);
  std::string output;
  double timeout_s = 5, discovery_s = 1;
  app.add_option("-o,--output", output,
                 "FILE.svg (rendered with `dot -Tsvg`) or FILE.dot; "
                 "default: DOT on stdout");
  app.add_option("--timeout", timeout_s, "seconds to wait for the registry");
  app.add_option("--discovery", discovery_s, "seconds to discover channel types");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    auto participant = tool.participant("oscar-graph");
    oscar::RegistryClient client(*participant, "graph");
    const std::chrono::milliseconds wait(static_cast<long>(timeout_s * 1000));
    const auto s = client.current_state(wait);
    if (!s) {
      fmt::print(stderr, "oscar graph: {}\n",
                 oscar::why_no_state(client, participant->domain(), wait));
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<long>(discovery_s * 1000)));
    const auto dot = to_dot(*client.latest(), participant->discovered_writers());
    if (output.empty()) {
      fmt::print("{}", dot);
      return 0;
    }
    const bool svg = output.size() > 4 && output.substr(output.size() - 4) == ".svg";
    const auto dot_file = svg ? output + ".dot" : output;
    {
      std::ofstream f(dot_file);
      f << dot;
      if (!f.flush()) {
        fmt::print(stderr, "oscar graph: cannot write '{}'\n", dot_file);
        return 1;
      }
    }
    if (svg) {
      const auto cmd = fmt::format("dot -Tsvg -o '{}' '{}'", output, dot_file);
      const int rc = std::system(cmd.c_str());
      std::remove(dot_file.c_str());
      if (rc != 0) {
        fmt::print(stderr, "oscar graph: `{}` failed (exit {}); is Graphviz installed?\n", cmd,
                   WEXITSTATUS(rc));
        return 1;
      }
    }
    fmt::print("oscar graph: wrote {}\n", output);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar graph: %s\n", e.what());
    return 1;
  }
}
