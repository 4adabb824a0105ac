// oscar-applets run SCENARIO.yaml [--json] [--svg FILE] — runs an applet scenario on the
// deterministic scheduler and prints the holder of every service after each step; with --live,
// on a booted system with every applet in a process of its own.
// oscar-applets ps [--json] — the plan of the running system's coordinator.
// oscar-applets graph [-o FILE.svg] — the same plan as a picture.
// oscar-applets add FILE.yaml / remove --applet NAME | --service NAME — change the running system.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <oscar/command_line.hpp>

#include "oscar/applets/dot.hpp"
#include "oscar/applets/scenario.hpp"
#ifdef OSCAR_APPLETS_LIVE
#include "change.hpp"
#include "live.hpp"
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
  bool live = false;
  oscar::tools::LiveOptions live_options;
  int settle_ms = static_cast<int>(live_options.settle.count());
  run->add_flag("--live", live,
                "Boot a temporary system (a free domain, loopback) with every applet in a process "
                "of its own and drive the timeline through the coordinator");
  run->add_option("--time-scale", live_options.time_scale,
                  "--live: multiply every time of the scenario by this on the real clock")
      ->capture_default_str();
  run->add_option("--settle-ms", settle_ms,
                  "--live: read a step's holders once the plan has not changed for this long")
      ->capture_default_str();
  bool print_system = false;
  run->add_flag("--print-system", print_system,
                "--live: print the system file that stands for the scenario, and boot nothing");
  oscar::tools::PsOptions ps;
  oscar::tools::add_ps(app, ps);
  oscar::tools::GraphOptions graph;
  oscar::tools::add_graph(app, graph);
  oscar::tools::ChangeOptions change;
  oscar::tools::add_change(app, change);
#endif
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
#ifdef OSCAR_APPLETS_LIVE
  if (change.add->parsed() || change.remove->parsed()) {
    try {
      return oscar::tools::run_change(change);
    } catch (const std::exception& e) {
      std::cerr << "oscar applets " << (change.add->parsed() ? "add" : "remove") << ": " << e.what()
                << "\n";
      return 2;
    }
  }
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
#ifdef OSCAR_APPLETS_LIVE
    if (live) {
      if (!dot_file.empty()) {
        throw std::invalid_argument(
            "--svg/--dot draws the offline run's final state; not with --live "
            "(oscar applets graph draws a running system's plan)");
      }
      live_options.settle = std::chrono::milliseconds(settle_ms);
      if (print_system) {
        std::cout << oscar::tools::live_system_yaml(scenario, "live", live_options);
        return 0;
      }
      const auto results = oscar::tools::run_live(scenario, file, live_options);
      std::cout << (json ? oscar::applets::format_json(results)
                         : oscar::applets::format_text(results));
      for (const auto& r : results) {
        if (!r.mismatches.empty()) return 1;
      }
      return 0;
    }
#endif
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
