// oscar applets ps [--json] and oscar applets graph [-o FILE.svg]: the plan of the running
// system's coordinator (docs/coordinator.md).
#include "ps.hpp"

#include <cstdio>
#include <optional>

#include "oscar/applets/dot.hpp"
#include "oscar/coordinator/plan_json.hpp"
#include "oscar/newest_sample.hpp"
#include "oscar/registry/system_options.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::tools {

void add_ps(CLI::App& app, PsOptions& options) {
  auto* ps = app.add_subcommand("ps", "The running system's services, their holders and applets");
  options.tool.add_to(*ps);
  ps->add_flag("--json", options.json,
               R"(Print JSON: {"services":{"<service>":{"holders","access","waiting"}},)"
               R"("applets":[{"name","process","state"}]})");
  ps->add_option("--timeout", options.timeout_s, "seconds to wait for the coordinator's plan");
  options.command = ps;
}

namespace {

// The plan the coordinator publishes, or nothing (and a message) if none arrives in time.
std::optional<AppletPlan> live_plan(const SystemOptions& tool, double timeout_s, const char* who) {
  auto participant = tool.participant(who);
  auto found = newest_sample(*participant, topics::applet_plan(),
                             std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)));
  if (!found.writer_found) {
    std::fprintf(stderr,
                 "oscar applets: no coordinator published its plan on domain %d within %.1f s "
                 "(does the system file have a coordinator: section?)\n",
                 participant->domain(), timeout_s);
  } else if (!found.sample) {
    std::fprintf(stderr,
                 "oscar applets: the coordinator on domain %d offers its plan but sent none "
                 "within %.1f s (is it hung? `oscar ps` shows its state)\n",
                 participant->domain(), 2 * timeout_s);
  }
  return std::move(found.sample);
}

}  // namespace

int run_ps(const PsOptions& options) {
  const auto plan = live_plan(options.tool, options.timeout_s, "oscar-applets-ps");
  if (!plan) return 1;
  const auto text =
      options.json ? coordinator::plan_json(*plan) + "\n" : coordinator::plan_table(*plan);
  std::fputs(text.c_str(), stdout);
  return 0;
}

void add_graph(CLI::App& app, GraphOptions& options) {
  auto* graph = app.add_subcommand("graph", "Draw the running system's plan (Graphviz)");
  options.tool.add_to(*graph);
  graph->add_option("-o,--output", options.output,
                    "FILE.svg (drawn with Graphviz; FILE.svg.dot is kept beside it) or FILE.dot; "
                    "without it the DOT text goes to stdout");
  graph->add_option("--timeout", options.timeout_s, "seconds to wait for the coordinator's plan");
  options.command = graph;
}

int run_graph(const GraphOptions& options) {
  const auto plan = live_plan(options.tool, options.timeout_s, "oscar-applets-graph");
  if (!plan) return 1;
  const auto dot = coordinator::plan_dot(*plan);
  if (options.output.empty()) {
    std::fputs(dot.c_str(), stdout);
    return 0;
  }
  if (!applets::write_picture(dot, options.output)) {
    std::fprintf(stderr,
                 "oscar applets graph: wrote %s.dot; Graphviz (dot) is not installed to draw "
                 "the SVG\n",
                 options.output.c_str());
    return 1;
  }
  std::printf("wrote %s\n", options.output.c_str());
  return 0;
}

}  // namespace oscar::tools
