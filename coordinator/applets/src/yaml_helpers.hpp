#pragma once
// YAML reading helpers shared by config.cpp and scenario.cpp (not installed).

#include <string>

#include <yaml-cpp/yaml.h>

namespace oscar::applets::internal {

/// @throws std::invalid_argument "file:line: message".
[[noreturn]] void fail_at(const YAML::Node& node, const std::string& file, const std::string& m);

/// A whole number. @throws std::invalid_argument naming `what` and the value.
long long number(const YAML::Node& node, const std::string& file, const std::string& what);

/// true or false; an absent node is false. @throws std::invalid_argument naming `what`.
bool flag(const YAML::Node& node, const std::string& file, const std::string& what);

}  // namespace oscar::applets::internal
