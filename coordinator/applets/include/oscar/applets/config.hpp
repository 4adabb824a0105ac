#pragma once
// Loading an applet system from YAML (the content of seed 000 Abb. 4.10): scheduler options,
// services with their configured dependencies, applets with parameters, bundles and provided
// services. The format is documented in docs/applets.md.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "oscar/applets/model.hpp"
#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {

/// An applet system as configured.
struct SystemConfig {
  Model model;
  SchedulerOptions options;
  /// Free parameters per applet and per service ("params:"), kept as text for the applets.
  std::map<std::string, std::map<std::string, std::string>> applet_params;
  std::map<std::string, std::map<std::string, std::string>> service_params;
  /// Bundles requested at start, in file order.
  std::vector<BundleId> requested_at_start;
};

/// Reads the system from a parsed YAML document; `file` names it in messages.
/// @throws std::invalid_argument "file:line: what: rule" on any bad input.
SystemConfig load_system(const YAML::Node& root, const std::string& file);

/// Services and applets to add to a running system (Scheduler::add), as read.
struct LoadedAddition {
  ModelAddition addition;
  std::map<std::string, std::map<std::string, std::string>> applet_params;
  std::map<std::string, std::map<std::string, std::string>> service_params;
  /// Bundles with `requested: true` (applet, bundle), in file order.
  std::vector<std::pair<std::string, std::string>> requested_at_start;
};

/// Reads services and applets to add to `current` (`services:` and/or `applets:`, in the
/// vocabulary of load_system), checked against it as the scheduler will: names in use, unknown
/// services, bad bundles. `file` names the text in messages.
/// @throws std::invalid_argument "file:line: what: rule" on any bad input.
LoadedAddition load_addition(const Model& current, const YAML::Node& root, const std::string& file);

/// Parses YAML text. @throws std::invalid_argument "file:line:column: malformed YAML: ...".
YAML::Node parse_yaml(const std::string& text, const std::string& file);

/// Reads a file. @throws std::invalid_argument if it cannot be read.
std::string read_text_file(const std::string& path);

/// "file:line" of a node (1-based line) for messages.
std::string where(const YAML::Node& node, const std::string& file);

/// A priority: a number or one of low, normal, high, system (intermediate numbers allowed).
/// @throws std::invalid_argument naming the value and the allowed names.
int parse_priority(const YAML::Node& node, const std::string& file);

}  // namespace oscar::applets
