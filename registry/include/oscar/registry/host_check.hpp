#pragma once
/// @file What `oscar boot` checks on each ssh host before it starts anything there (docs/boot.md,
/// "Booting over SSH"): that the host answers over ssh, runs the same OSCAR version, has the
/// system file at the same path with the same content, and has every program and plugin its
/// modules need. Boot runs `oscar-monitor --check` there over ssh; the monitor runs
/// check_this_host() and boot reads its answer with explain_host_check().

#include <optional>
#include <string>
#include <vector>

#include "oscar/registry/launch_command.hpp"
#include "oscar/registry/system_spec.hpp"

namespace oscar {

/// The OSCAR version of this build ("0.1.0"), the same in every program of one build.
std::string oscar_version();

/// A fingerprint of a file's content (64-bit FNV-1a, hex): equal content, equal fingerprint.
/// It tells a stale copy from a current one; it is no protection against a forged one.
std::string content_fingerprint(const std::string& content);

/// The file's content.
/// @throws std::invalid_argument "<path>: cannot read the file".
std::string read_text_file(const std::string& path);

/// The remote side: what is missing or different on `host` for running its modules of the
/// system file at `file`, whose content boot fingerprinted as `expected_fingerprint`. One line
/// per problem, each saying what to install or copy where; empty when the host is ready.
/// `program_path` maps a module's program (oscar-run, ...) to the file that must be there.
std::vector<std::string> check_this_host(const std::string& file, const std::string& host,
                                         const std::string& expected_fingerprint,
                                         const std::vector<std::string>& plugin_path,
                                         const ProgramPath& program_path);

/// Why this host cannot run a RouDi for `zero_copy:` (this OSCAR built without iceoryx, or no
/// iox-roudi on PATH), naming what to install; nothing when it can. Boot asks for the hosts of
/// this machine, check_this_host() for an ssh host.
std::optional<std::string> zero_copy_unavailable();

/// The first line `oscar-monitor --check` prints: "oscar-monitor <version>".
std::string check_banner();

/// Boot's side: the command that checks `host` (an ssh host of `system`, whose file is at the
/// absolute path `file` on both machines) with the monitor at `monitor` (absolute).
std::vector<std::string> host_check_command(const HostSpec& host, const std::string& file,
                                            const std::string& monitor);

/// Boot's side of `--copy-system-file`: the command that writes the content it is given on its
/// stdin to the same absolute path `file` on `host` (an ssh host), creating the folder and
/// replacing what is there (through a temporary file beside it, so a reader never sees half).
std::vector<std::string> copy_system_file_command(const HostSpec& host, const std::string& file);

/// What boot says about a check's outcome: nothing (std::nullopt) when the host is ready,
/// otherwise one message naming the host and the cause — unreachable, authentication refused,
/// host key not trusted, version mismatch, missing program, or what the host reported.
std::optional<std::string> explain_host_check(const HostSpec& host, const std::string& monitor,
                                              int exit_code, const std::string& output);

}  // namespace oscar
