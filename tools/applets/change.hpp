#pragma once
// `oscar applets add FILE.yaml` and `oscar applets remove --applet NAME | --service NAME`:
// services and applets added to and removed from the running system's coordinator (built only
// with the framework; docs/coordinator.md, "Adding and removing at run time").

#include <CLI/CLI.hpp>

#include "oscar/registry/system_options.hpp"

namespace oscar::tools {

struct ChangeOptions {
  SystemOptions tool;
  std::string file;     // add: the spec
  std::string applet;   // remove
  std::string service;  // remove
  double timeout_s = 10;
  CLI::App* add = nullptr;
  CLI::App* remove = nullptr;
};

/// Adds the subcommands `add` and `remove` to `app`.
void add_change(CLI::App& app, ChangeOptions& options);
/// Sends the addition or removal to the coordinator and prints its answer: 0 if it was taken,
/// 1 if the coordinator refused it (its reason on stderr), 2 if it could not be asked.
int run_change(const ChangeOptions& options);

}  // namespace oscar::tools
