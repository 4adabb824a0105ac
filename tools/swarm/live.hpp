#pragma once
// oscar swarm submit and oscar swarm status: jobs to the running system's coordinator and what
// its swarm looks like (docs/swarm.md, "The live swarm").

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "oscar/registry/system_options.hpp"

namespace oscar::swarm::tools {

struct SubmitOptions {
  SystemOptions system;
  std::string file;               ///< operations as in a problem file, times from now
  std::vector<std::string> jobs;  ///< --job: one job spec as YAML, scheduled
  double timeout_s = 10;
  bool json = false;
  CLI::App* command = nullptr;
};

struct StatusOptions {
  SystemOptions system;
  double timeout_s = 3;
  bool json = false;
  CLI::App* command = nullptr;
};

void add_submit(CLI::App& app, SubmitOptions& options);
void add_status(CLI::App& app, StatusOptions& options);

/// Exit codes: 0 every request committed, 1 a request was refused or aborted, 2 bad input or no
/// coordinator answered.
int run_submit(const SubmitOptions& options);
int run_status(const StatusOptions& options);

}  // namespace oscar::swarm::tools
