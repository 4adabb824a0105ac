// oscar-swarm: `oscar swarm plan PROBLEM.yaml|json [-o SCHEDULE.json] [--svg FILE] [--st NODE]
// [--seed N]`; with the framework also `oscar swarm submit`, `status` and `snapshot` (live.hpp).
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include <cerrno>
#include <cstring>
#include <exception>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <stdexcept>

#include "oscar/swarm/problem.hpp"
#include "oscar/swarm/problem_runner.hpp"
#include "svg.hpp"
#ifdef OSCAR_SWARM_LIVE
#include "live.hpp"
#endif

namespace {

// An output that could not be written: exit code 1, where bad input is 2.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes `text` to the file `path`, or to the standard output if `path` is empty; a failure to
// open, write or close is an OutputError with the system's reason.
void write_output(const std::string& path, const std::string& text) {
  if (path.empty()) {
    std::cout << text << std::flush;
    if (!std::cout) {
      throw OutputError(fmt::format("cannot write the standard output: {}", std::strerror(errno)));
    }
    return;
  }
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) throw OutputError(fmt::format("cannot write '{}': {}", path, std::strerror(errno)));
}

// Runs a command that writes its output through write_output(): exit code 0, 1 for an output
// that could not be written, 2 for anything else (bad input, nobody answered), said on stderr.
int run_writing(const char* command, const std::function<void()>& run) {
  try {
    run();
  } catch (const OutputError& e) {
    std::cerr << "oscar swarm " << command << ": " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "oscar swarm " << command << ": " << e.what() << "\n";
    return 2;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar swarm: the swarm planner (seed 002)"};
  app.require_subcommand(1);
  auto* plan = app.add_subcommand("plan", "run a planning problem and write the schedule as JSON");
  std::string problem_path, output, svg, st_node;
  plan->add_option("problem", problem_path, "problem file (YAML or JSON)")->required();
  plan->add_option("-o,--output", output, "write the schedule JSON here instead of stdout");
  auto* svg_option =
      plan->add_option("--svg", svg, "draw world, paths and jobs into this SVG file");
  plan->add_option("--st", st_node, "with --svg: draw the s-t diagram of this node's trajectory")
      ->needs(svg_option);
  std::optional<unsigned> seed;
  plan->add_option("--seed", seed, "seed of the planner's random choices (overrides the file)");
#ifdef OSCAR_SWARM_LIVE
  oscar::swarm::tools::SubmitOptions submit;
  oscar::swarm::tools::StatusOptions status;
  oscar::swarm::tools::SnapshotOptions snapshot;
  oscar::swarm::tools::add_submit(app, submit);
  oscar::swarm::tools::add_status(app, status);
  oscar::swarm::tools::add_snapshot(app, snapshot);
  oscar::swarm::tools::WorldOptions world;
  oscar::swarm::tools::add_world(app, world);
#endif
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
#ifdef OSCAR_SWARM_LIVE
  if (snapshot.command->parsed()) {
    return run_writing("snapshot", [&] {
      write_output(snapshot.output, oscar::swarm::tools::snapshot_svg(snapshot));
    });
  }
  if (submit.command->parsed() || status.command->parsed() || world.command->parsed()) {
    const char* which = submit.command->parsed()   ? "submit"
                        : status.command->parsed() ? "status"
                                                   : "world";
    try {
      return submit.command->parsed()   ? oscar::swarm::tools::run_submit(submit)
             : status.command->parsed() ? oscar::swarm::tools::run_status(status)
                                        : oscar::swarm::tools::run_world(world);
    } catch (const std::exception& e) {
      std::cerr << "oscar swarm " << which << ": " << e.what() << "\n";
      return 2;
    }
  }
#endif
  return run_writing("plan", [&] {
    auto problem = oscar::swarm::load_problem(problem_path);
    if (seed) problem.settings.seed = *seed;
    oscar::swarm::ProblemRunner runner(problem);
    runner.run();
    write_output(output, runner.to_json() + "\n");
    if (!svg.empty()) {
      write_output(svg, st_node.empty() ? oscar::swarm::tools::world_svg(runner.scheduler())
                                        : oscar::swarm::tools::st_svg(runner.scheduler(), st_node));
    }
  });
}
