#pragma once
// What `oscar new-module` generates from: a module's name, ports and parameters, checked.

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace oscar::new_module {

struct Port {
  /// type: a standard cue type without "oscar::" (Bool, GvImage, ...) or one of the module's own
  std::string name, type;
};

struct Param {
  std::string name, type, default_value;  ///< type: bool, int, int64, double, string, duration
};

struct ModuleSpec {
  std::string name;  ///< the kernel type and folder, snake_case
  std::vector<Port> inputs, outputs;
  std::vector<Param> params;
  /// Cue types of the module's own (CamelCase), declared in <name>_types.idl in IDL module <name>.
  std::vector<std::string> types;
  bool out_of_tree = false;

  /// Parses the command line's "name:Type" and "name:type=default".
  /// @throws std::invalid_argument naming the argument and the rule it breaks.
  static Port parse_port(const std::string& text, const char* option);
  static Param parse_param(const std::string& text);

  /// Checks names (C++ identifiers, not keywords, unique across ports and params), cue types,
  /// parameter defaults, that there is an output, and that `taken` (existing kernel types and
  /// folders) does not hold the name.
  /// @throws std::invalid_argument with a clear message.
  void validate(const std::set<std::string>& taken) const;

  /// "line_fuser" -> "LineFuser".
  std::string class_name() const;

  /// The C++ type of a port's cue type: "oscar::Bool", or "<name>::T" for a type of its own.
  std::string cpp_cue_type(const std::string& type) const;
  bool is_own_type(const std::string& type) const;
};

/// The files of the module, by path relative to its folder.
std::map<std::string, std::string> generate(const ModuleSpec& spec);

/// Writes the module into `dir/<name>/` (which must not exist); in-tree, also appends
/// `add_subdirectory(<name>)` to `dir/CMakeLists.txt` if that file exists. Returns the folder.
/// @throws std::runtime_error if the folder exists or cannot be written.
std::filesystem::path write_module(const ModuleSpec& spec, const std::filesystem::path& dir);

}  // namespace oscar::new_module
