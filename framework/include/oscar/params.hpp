#pragma once
/// @file ParamSpec: a kernel's parameters, each listed once for YAML, set_param, checks and docs.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace YAML {
class Node;
}

namespace oscar {

/// One parameter: its name, help, type and the accessors into the kernel's Params struct.
struct ParamField {
  std::string name;
  std::string type;  ///< "bool", "int", "double", "string" or "duration"
  std::string help;
  std::optional<double> min, max;    ///< for numbers and durations (in seconds)
  std::vector<std::string> choices;  ///< for strings; empty = any
  bool runtime = true;               ///< may be changed by set_param while the kernel runs
  std::function<void(const YAML::Node&)> set;  ///< parses, checks, assigns; throws on bad input
  std::function<std::string()> get;            ///< the current value as YAML scalar text

  ParamField& range(double lo, double hi) {
    min = lo;
    max = hi;
    return *this;
  }
  ParamField& at_least(double lo) {
    min = lo;
    return *this;
  }
  ParamField& one_of(std::vector<std::string> allowed) {
    choices = std::move(allowed);
    return *this;
  }
  ParamField& fixed() {
    runtime = false;
    return *this;
  }
};

/// The parameters of one kernel. Params structs list their fields in `describe(ParamSpec&)`.
class ParamSpec {
 public:
  explicit ParamSpec(std::string owner = "kernel") : owner_(std::move(owner)) {}
  // Fields refer back to the spec and to each other's storage: never copied or moved.
  ParamSpec(const ParamSpec&) = delete;
  ParamSpec& operator=(const ParamSpec&) = delete;

  ParamField& field(std::string name, bool& value, std::string help);
  ParamField& field(std::string name, int& value, std::string help);
  ParamField& field(std::string name, std::int64_t& value, std::string help);
  ParamField& field(std::string name, double& value, std::string help);
  ParamField& field(std::string name, std::string& value, std::string help);
  ParamField& field(std::string name, std::chrono::nanoseconds& value, std::string help);

  /// Sets a parameter from a YAML scalar.
  /// @throws std::invalid_argument naming the owner, the parameter and the rule broken.
  void set(std::string_view name, const YAML::Node& value);
  /// Sets a parameter from text, parsed as a YAML scalar (what `set_param` carries).
  void set_text(std::string_view name, std::string_view text);
  /// Sets every key of a YAML map; unknown keys are errors that list the known parameters.
  void set_all(const YAML::Node& map);
  /// The current values as a YAML map text (for the round trip and `oscar info`).
  std::string to_yaml() const;

  const std::deque<ParamField>& fields() const { return fields_; }
  const ParamField* find(std::string_view name) const;
  const std::string& owner() const { return owner_; }

 private:
  ParamField& add(ParamField f);
  std::string known_names() const;

  std::string owner_;
  std::deque<ParamField> fields_;  // deque: references stay valid
};

}  // namespace oscar
