// oscar-applets run SCENARIO.yaml [--json] [--svg FILE] — runs an applet scenario on the
// deterministic scheduler and prints the holder of every service after each step.
// oscar-applets ps [--json] — the plan of the running system's coordinator.
// oscar-applets graph [-o FILE.svg] — the same plan as a picture.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <oscar/command_line.hpp>

#include "oscar/applets/dot.hpp"
#include "oscar/applets/scenario.hpp"
#ifdef OSCAR_APPLETS_LIVE
#include "ps.hpp"
#endif

int main(int argc, char** argv) {
  CLI::App app{"Applet scheduler scenarios (seed 000): oscar applets run SCENARIO.yaml"};
  app.require_subcommand(1);
  auto* run = app.add_subcommand("run", "Run a scenario and print the holder of every service");
  std::string file;
  bool json = false;
  std::string dot_file;
  run->add_option("scenario", file, "Scenario YAML file (docs/applets.md)")->required();
  run->add_flag("--json", json, "Print JSON: {\"steps\":[{\"event\",\"t_ms\",\"holders\"}]}");
  run->add_option("--svg,--dot", dot_file,
                  "Write a picture of the final state: FILE.svg (drawn with Graphviz; FILE.svg.dot "
                  "is kept beside it) or FILE.dot");
#ifdef OSCAR_APPLETS_LIVE
  oscar::tools::PsOptions ps;
  oscar::tools::add_ps(app, ps);
  oscar::tools::GraphOptions graph;
  oscar::tools::add_graph(app, graph);
#endif
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
#ifdef OSCAR_APPLETS_LIVE
  if (ps.command->parsed() || graph.command->parsed()) {
    try {
      return ps.command->parsed() ? oscar::tools::run_ps(ps) : oscar::tools::run_graph(graph);
    } catch (const std::exception& e) {
      std::cerr << "oscar applets " << (ps.command->parsed() ? "ps" : "graph") << ": " << e.what()
                << "\n";
      return 2;
    }
  }
#endif
  try {
    const auto scenario = oscar::applets::Scenario::load_file(file);
    oscar::applets::Scheduler final_state(scenario.system().model, scenario.system().options);
    const auto results = scenario.run(&final_state);
    std::cout << (json ? oscar::applets::format_json(results)
                       : oscar::applets::format_text(results));
    if (!dot_file.empty()) oscar::applets::write_picture(final_state, dot_file);
    for (const auto& r : results) {
      if (!r.mismatches.empty()) return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "oscar applets run: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
