#pragma once
// oscar swarm submit, status and snapshot: jobs to the running system's coordinator, what its
// swarm looks like, and a picture of it (docs/swarm.md, "The live swarm").

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

struct SnapshotOptions {
  SystemOptions system;
  std::string output;  ///< -o: the SVG file
  double timeout_s = 3;
  CLI::App* command = nullptr;
};

void add_submit(CLI::App& app, SubmitOptions& options);
void add_status(CLI::App& app, StatusOptions& options);
void add_snapshot(CLI::App& app, SnapshotOptions& options);

/// Exit codes: 0 every request committed, 1 a request was refused or aborted, 2 bad input or no
/// coordinator answered.
int run_submit(const SubmitOptions& options);
int run_status(const StatusOptions& options);

/// The picture of the running swarm now: the world, where each robot is, its committed path from
/// now on and its jobs to do.
/// @throws std::runtime_error when no coordinator publishes a plan within the timeout.
std::string snapshot_svg(const SnapshotOptions& options);

}  // namespace oscar::swarm::tools
