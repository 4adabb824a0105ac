#pragma once
// Reading the `services:` and `coordinator:` sections of a system file (not installed).

#include <yaml-cpp/yaml.h>

#include "oscar/registry/system_spec.hpp"

namespace oscar::internal {

/// Reads `services:` into s.services, checking them against s.modules (read before).
/// @throws std::invalid_argument "file:line: ..." naming the service and the rule.
void parse_services(SystemSpec& s, const YAML::Node& node);

/// Reads `coordinator:` into s.coordinator (its module is made by the caller).
/// @throws std::invalid_argument "file:line: ...".
void parse_coordinator(SystemSpec& s, const YAML::Node& node);

}  // namespace oscar::internal
