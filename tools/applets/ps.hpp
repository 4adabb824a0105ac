#pragma once
// `oscar applets ps` and `oscar applets graph`: the running system's plan (built only with the
// framework).

#include <CLI/CLI.hpp>

#include "oscar/registry/system_options.hpp"

namespace oscar {
namespace tools {

struct PsOptions {
  SystemOptions tool;
  bool json = false;
  double timeout_s = 3;
  CLI::App* command = nullptr;
};

struct GraphOptions {
  SystemOptions tool;
  std::string output;  // FILE.svg or FILE.dot; empty: DOT on stdout
  double timeout_s = 3;
  CLI::App* command = nullptr;
};

/// Adds the subcommand `ps` to `app`.
void add_ps(CLI::App& app, PsOptions& options);
/// Prints the plan the coordinator publishes; 1 if none arrives in time.
int run_ps(const PsOptions& options);

/// Adds the subcommand `graph` to `app`.
void add_graph(CLI::App& app, GraphOptions& options);
/// Draws the plan the coordinator publishes; 1 if none arrives in time.
int run_graph(const GraphOptions& options);

}  // namespace tools
}  // namespace oscar
