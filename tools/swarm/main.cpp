// oscar-swarm: `oscar swarm plan PROBLEM.yaml|json [-o SCHEDULE.json] [--svg FILE] [--st NODE]`.
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include <exception>
#include <fstream>
#include <iostream>

#include "oscar/swarm/problem.hpp"
#include "oscar/swarm/problem_runner.hpp"
#include "svg.hpp"

int main(int argc, char** argv) {
  CLI::App app{"oscar swarm: the swarm planner (seed 002)"};
  app.require_subcommand(1);
  auto* plan = app.add_subcommand("plan", "run a planning problem and write the schedule as JSON");
  std::string problem_path, output, svg, st_node;
  plan->add_option("problem", problem_path, "problem file (YAML or JSON)")->required();
  plan->add_option("-o,--output", output, "write the schedule JSON here instead of stdout");
  plan->add_option("--svg", svg, "draw world, paths and jobs into this SVG file");
  plan->add_option("--st", st_node, "with --svg: draw the s-t diagram of this node's trajectory");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    const auto problem = oscar::swarm::load_problem(problem_path);
    oscar::swarm::ProblemRunner runner(problem);
    runner.run();
    const std::string json = runner.to_json();
    if (output.empty()) {
      std::cout << json << "\n";
    } else {
      std::ofstream(output) << json << "\n";
    }
    if (!svg.empty()) {
      std::ofstream out(svg);
      out << (st_node.empty() ? oscar::swarm::tools::world_svg(runner.scheduler())
                              : oscar::swarm::tools::st_svg(runner.scheduler(), st_node));
    }
  } catch (const std::exception& e) {
    std::cerr << "oscar swarm plan: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
