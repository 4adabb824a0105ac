#pragma once
/// @file Runs a short command to its end and keeps what it wrote: boot's check of an ssh host
/// and the copy of the system file there (docs/boot.md, "Booting over SSH").

#include <chrono>
#include <string>
#include <vector>

namespace oscar {

/// Output and exit code of a command run to its end.
struct CommandResult {
  int exit_code = -1;  ///< -1: killed after the timeout, or ended by a signal
  std::string output;  ///< stdout and stderr together
};

/// Runs `argv` (looked up on PATH) with `input` on its stdin, in a process group of its own
/// (Ctrl-C is the caller's to handle), and waits for it at most `timeout`, then kills it.
/// @throws std::runtime_error if it cannot be started.
CommandResult run_command(const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                          const std::string& input = "");

}  // namespace oscar
