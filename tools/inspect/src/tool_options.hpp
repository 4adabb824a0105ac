#pragma once
// The options every inspection tool shares: which system (domain, network) to look at.

#include <string>

#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

namespace oscar::inspect {

struct ToolOptions {
  std::string system_file, host;
  int domain = -1;
  void add_to(CLI::App& app) {
    app.add_option("--system", system_file, "system file (its domain and network)");
    app.add_option("--host", host, "the host this runs on (with --system)");
    app.add_option("-d,--domain", domain,
                   "DDS domain (default: the system file's, $OSCAR_DOMAIN, the system booted on "
                   "this machine, or 0)");
  }
};

}  // namespace oscar::inspect
