#pragma once
// A Graphviz picture of an applet system (seed 000 Abb. 4.11): applets with their bundles and
// priorities, services with their holders, resources coloured by state, dependencies.

#include <string>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {

/// `s` as a DOT string literal (quotes and backslashes escaped, newlines as \n).
std::string dot_quote(const std::string& s);

/// DOT text of the scheduler's current state. Always available.
std::string to_dot(const Scheduler& scheduler);

/// Writes the picture: DOT text to `path`; if `path` ends in ".svg" the DOT goes to `path`.dot
/// and Graphviz `dot` renders the SVG when installed. Returns false if rendering was skipped.
/// @throws std::invalid_argument if the file cannot be written.
bool write_picture(const Scheduler& scheduler, const std::string& path);
/// The same for DOT text made elsewhere (the live plan, `oscar applets graph`).
bool write_picture(const std::string& dot, const std::string& path);

}  // namespace oscar::applets
