#pragma once
/// @file What every OSCAR program does the same way: find the programs installed beside it, and
/// turn SIGINT/SIGTERM into an orderly stop.

#include <signal.h>

#include <chrono>
#include <filesystem>
#include <string>

namespace oscar {

/// The directory of the running program (where oscar-run, oscar-monitor, ... are installed).
std::filesystem::path program_dir();
/// `<program_dir>/<program>`.
std::string sibling_program(const std::string& program);

/// Blocks SIGINT and SIGTERM in this thread and every thread started after it, so they can be
/// waited for with wait_for_stop(). Call first thing in main().
sigset_t block_stop_signals();
/// True if SIGINT or SIGTERM arrived within `timeout`.
bool wait_for_stop(const sigset_t& signals, std::chrono::milliseconds timeout);

}  // namespace oscar
