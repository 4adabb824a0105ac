#pragma once
/// @file How every oscar tool reads its command line: `--help` prints the usage and exits 0; a
/// usage error (unknown option, missing argument, bad value) prints what is wrong and how to
/// ask for help, and exits 2 — the exit code the docs give for usage errors, never one of
/// CLI11's own (105-113).

#include <CLI/CLI.hpp>

namespace oscar {

/// Parses the command line into `app`. Returns -1 when the tool should go on, otherwise the
/// code it should exit with (0 after --help, 2 after a usage error).
inline int parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints the help or the error
    return code == 0 ? 0 : 2;
  }
}

}  // namespace oscar

/// Use in main() in place of CLI11_PARSE.
#define OSCAR_PARSE_COMMAND_LINE(app, argc, argv)                                 \
  do {                                                                            \
    if (const int oscar_exit_code = ::oscar::parse_command_line(app, argc, argv); \
        oscar_exit_code >= 0) {                                                   \
      return oscar_exit_code;                                                     \
    }                                                                             \
  } while (false)
