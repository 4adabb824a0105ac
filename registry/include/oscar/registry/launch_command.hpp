#pragma once
/// @file The command lines that start processes on a system's hosts: as they are (local), in a
/// network namespace (`ip netns exec`), or over ssh (a template; tests only build it).

#include <string>
#include <vector>

#include "oscar/registry/system_spec.hpp"

namespace oscar {

/// `argv` wrapped so it runs on `host`. For ssh the remote command is one shell-quoted string.
std::vector<std::string> on_host(const HostSpec& host, const std::vector<std::string>& argv);

/// The module process: `oscar-run FILE --module M --incarnation N --domain D`, under
/// gdbserver (127.0.0.1:PORT) or valgrind (its log beside the module's) if the YAML says so.
/// `oscar_run` is the program to start (the coordinator's module: its `program`,
/// oscar-coordinator); `log_dir` the monitor's directory for the module.
std::vector<std::string> module_command(const SystemSpec& system, const SystemModule& module,
                                        unsigned incarnation, const std::string& oscar_run,
                                        const std::string& log_dir);

/// Quotes one word for a POSIX shell.
std::string shell_quote(const std::string& word);

}  // namespace oscar
