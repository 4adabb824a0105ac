#pragma once
// `oscar applets ps` (built only with the framework).

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

/// Adds the subcommand `ps` to `app`.
void add_ps(CLI::App& app, PsOptions& options);
/// Prints the plan the coordinator publishes; 1 if none arrives in time.
int run_ps(const PsOptions& options);

}  // namespace tools
}  // namespace oscar
