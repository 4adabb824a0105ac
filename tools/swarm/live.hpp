#pragma once
// oscar swarm submit, status and snapshot: jobs to the running system's coordinator, what its
// swarm looks like, and a picture of it (docs/swarm.md, "The live swarm").

#include <cstdint>
#include <string>
#include <vector>

#include <oscar/swarm.h>
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

/// oscar swarm world add NAME ... | remove NAME... (world.cpp).
struct WorldOptions {
  SystemOptions system;
  std::string name;                ///< add: the obstacle's name
  std::vector<std::string> names;  ///< remove
  std::string polygon;             ///< add: a standing obstacle, [[x, y], ...]
  std::string shape;               ///< add: a moving one's shape around its origin
  std::string path;                ///< with shape: [[x, y, t], ...], t in seconds from now
  std::string loop;                ///< with shape: [[x, y, t], ...] from 0 to the period
  double timeout_s = 10;
  bool json = false;
  CLI::App* add = nullptr;
  CLI::App* remove = nullptr;
  CLI::App* command = nullptr;
};

void add_submit(CLI::App& app, SubmitOptions& options);
void add_world(CLI::App& app, WorldOptions& options);
/// Exit codes as run_submit.
int run_world(const WorldOptions& options);
void add_status(CLI::App& app, StatusOptions& options);
void add_snapshot(CLI::App& app, SnapshotOptions& options);

/// Exit codes: 0 every request committed, 1 a request was refused or aborted, 2 bad input or no
/// coordinator answered.
int run_submit(const SubmitOptions& options);
/// Sends `requests` to the coordinator as `oscar swarm <command>` and waits for each outcome
/// (`timeout_s` each), printing them (as JSON lines with `json`); exit codes as run_submit.
int send_requests(const SystemOptions& system, const std::string& command,
                  const std::vector<SwarmRequest>& requests, double timeout_s, bool json,
                  std::int64_t now);
int run_status(const StatusOptions& options);

/// The picture of the running swarm now: the world, where each robot is, its committed path from
/// now on and its jobs to do.
/// @throws std::runtime_error when no coordinator publishes a plan within the timeout.
std::string snapshot_svg(const SnapshotOptions& options);

}  // namespace oscar::swarm::tools
