#pragma once
/// @file The command lines that start processes on a system's hosts: as they are (local), in a
/// network namespace (`ip netns exec`), or over ssh (docs/boot.md, "Booting over SSH").

#include <functional>
#include <string>
#include <vector>

#include "oscar/registry/system_spec.hpp"

namespace oscar {

/// `argv` wrapped so it runs on `host`. For ssh the remote command is one shell-quoted string,
/// after the host's `ssh_options` (`-o Key=Value`) and keep-alives that end a dead connection.
std::vector<std::string> on_host(const HostSpec& host, const std::vector<std::string>& argv);

/// Maps one of OSCAR's program names (oscar-run, oscar-coordinator, oscar-applet) to the program
/// to start (the monitor's: the copy next to itself).
using ProgramPath = std::function<std::string(const std::string&)>;

/// The module process: `oscar-run FILE --module M --incarnation N --domain D` (the coordinator's
/// module: its `program`, oscar-coordinator; a process of applets: oscar-applet), under
/// gdbserver (127.0.0.1:PORT) or valgrind (its log beside the module's) if the YAML says so.
/// `log_dir` is the monitor's directory for the module.
std::vector<std::string> module_command(const SystemSpec& system, const SystemModule& module,
                                        unsigned incarnation, const ProgramPath& program_path,
                                        const std::string& log_dir);

/// What a monitor starts for a LaunchRequest: module `module` of `system` (which must run on
/// `host`) as module_command() builds it, and `--restore restore` unless that is empty.
/// Nothing of the command comes from the request but the module's name, the incarnation and the
/// configuration to restore.
/// @throws std::invalid_argument naming the module and the rule: not a module of the system,
/// or one of another host.
std::vector<std::string> launch_command(const SystemSpec& system, const std::string& host,
                                        const std::string& module, unsigned incarnation,
                                        const std::string& restore, const std::string& log_dir,
                                        const ProgramPath& program_path);

/// Quotes one word for a POSIX shell.
std::string shell_quote(const std::string& word);

}  // namespace oscar
