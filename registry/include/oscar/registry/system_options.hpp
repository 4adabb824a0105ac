#pragma once
/// @file SystemOptions: which running system a command-line tool looks at, read the same way by
/// every tool (`--system FILE [--host H]`, `-d/--domain D`, else $OSCAR_DOMAIN, else the system
/// `oscar boot` runs on this machine).

#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/registry/registry_client.hpp"

namespace oscar {

struct SystemOptions {
  std::string system_file;  ///< --system: that system's domain and network
  std::string host;         ///< --host: the host of the system file this tool runs on
  int domain = -1;          ///< -d/--domain; -1 when not given

  /// Adds --system, --host and -d/--domain to `app`.
  void add_to(CLI::App& app);
  /// Adds -d/--domain alone, for tools that make their own loopback participant (record, replay).
  void add_domain_to(CLI::App& app);
  /// The participant of tool `name` on the chosen system (see tool_participant()).
  /// @throws std::invalid_argument if several systems run here and none was named.
  std::unique_ptr<DdsParticipant> participant(const std::string& name,
                                              ToolAuthority authority = ToolAuthority::kLook) const;
  /// The domain alone: -d, else the system file's, else $OSCAR_DOMAIN, else the system booted on
  /// this machine, else 0. @throws std::invalid_argument as participant() does.
  int resolved_domain() const;
};

}  // namespace oscar
