#pragma once
/// @file What one module process hosts: parsed from YAML (a `modules:` entry of a system file or
/// an oscar-run fragment) and checked against the seed's multi-core rules (seed 004 §2.2).

#include <chrono>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "oscar/input.hpp"
#include "oscar/network.hpp"

namespace oscar {

/// A kernel's mode (docs/kernels.md): continuous with a cycle, single step with a trigger, or off.
struct ModeSpec {
  enum class Kind { kContinuous, kSingleStep, kDeactivated };
  Kind kind = Kind::kSingleStep;
  std::chrono::nanoseconds cycle{0};  ///< continuous only
  std::string trigger;  ///< single step: "" (default), "command", "module" or "input:<name>"

  /// "continuous(33ms)", "single_step(input:image)", "deactivated".
  std::string describe() const;
  /// Parses `single_step`, `deactivated`, `continuous:33ms`, `{continuous: 33ms}`,
  /// `{single_step: {trigger: image}}`. @throws std::invalid_argument naming the rule.
  static ModeSpec parse(const YAML::Node& node);
  static ModeSpec parse_text(const std::string& text);
};
const char* to_string(ModeSpec::Kind kind);

struct InputWiring {
  std::string source;  ///< "<kernel>/<channel>"; empty = not wired
  std::optional<Transfer> transfer;
  std::optional<std::size_t> depth;
};

struct KernelSpec {
  std::string type;
  std::string name;
  YAML::Node params;
  std::map<std::string, InputWiring> inputs;
  std::optional<ModeSpec> mode;
  std::optional<bool> stub;  ///< overrides the module's `stub` for this kernel
  std::string where;         ///< "file:line" of its YAML entry, for messages
};

/// What the frame does when a kernel's on_activate(), process() or stub() throws `after` times
/// in a row (a call that returns starts the count again). Every failure is counted and shown by
/// `oscar ps` whatever the action.
struct KernelErrorPolicy {
  enum class Action {
    kContinue,    ///< keep calling it (the log holds repeats back, with a count)
    kDeactivate,  ///< deactivate the kernel; the coordinator may activate it again
    kRestart,     ///< end the process (exit code kKernelFailureExit): the registry restarts it
  };
  Action action = Action::kRestart;
  int after = 3;

  /// Parses `restart`, `continue`, `deactivate` or `{action: A, after: N}`.
  /// @throws std::invalid_argument naming the rule.
  static KernelErrorPolicy parse(const YAML::Node& node);
};
const char* to_string(KernelErrorPolicy::Action action);

/// oscar-run's exit code when the kernel-error policy ends the process.
inline constexpr int kKernelFailureExit = 3;

struct ModuleSpec {
  std::string name;
  std::string host;
  std::optional<int> domain;
  std::vector<KernelSpec> kernels;
  ModeSpec mode;
  bool stub = false;
  NetworkConfig network;
  std::string where;
  /// Which start of this module this is (1 = first; the registry counts restarts).
  std::uint32_t incarnation = 1;
  /// Start with all kernels suspended (a restart waits for its configuration to be re-applied).
  bool start_suspended = false;
  /// Liveliness lease of the module's heartbeat (default 300 ms; docs/boot.md).
  std::chrono::milliseconds lease{300};
  /// A kernel call running longer than this stops the heartbeat: the registry sees a hang.
  std::chrono::milliseconds watchdog{2000};
  /// What a kernel that keeps throwing leads to (default: restart the module after 3).
  KernelErrorPolicy on_kernel_error;
  /// Plugin files and folders of plugins the file names (`plugins:`), absolute: searched before
  /// $OSCAR_PLUGIN_PATH (with_plugins()).
  std::vector<std::string> plugins;
  /// The names of all modules of the system file it comes from, the coordinator's included; empty
  /// for a module file. A configuration command written from the process of one of them is that
  /// module's, whatever sender it names (Module::apply).
  std::vector<std::string> system_modules;

  /// Parses one module map. `file` names the source in messages ("file:line: ...").
  /// @throws std::invalid_argument for unknown keys, missing names, duplicate kernel names,
  ///         bad modes or wiring.
  static ModuleSpec from_yaml(const YAML::Node& node, const std::string& file);
  /// Loads a file holding either one module map or a system file with `modules:`; `module`
  /// picks one of a system file's modules. YAML syntax errors are reported as file:line:col.
  static ModuleSpec load(const std::string& path, const std::string& module = "");

  const KernelSpec* find_kernel(const std::string& kernel_name) const;

  /// The `plugins:` key of a system or module file: one path or a list, relative to the file's
  /// folder; each must exist. @throws std::invalid_argument "file:line: plugins: ...".
  static std::vector<std::string> plugins_of(const YAML::Node& root, const std::string& file);
  /// Applies what a running incarnation had been configured to (the registry passes it to a
  /// restarted module): `{kernel: {mode: M, stub: B, params: {..}, inputs: {in: k/ch}}}`.
  /// @throws std::invalid_argument naming the kernel and key.
  void restore(const YAML::Node& state);
  /// The mode a kernel starts in: its own, or derived from the module's mode (a continuous
  /// module runs its first kernel continuously and triggers the others).
  ModeSpec effective_mode(const KernelSpec& kernel) const;
};

/// Loads a YAML file; syntax errors become std::invalid_argument "file:line:col: message".
YAML::Node load_yaml_file(const std::string& path);

/// @throws std::invalid_argument "file:line: <what>: unknown key 'k' (allowed: ...)".
void check_yaml_keys(const YAML::Node& map, const std::string& file, const std::string& what,
                     std::initializer_list<const char*> allowed);

/// "file:line" of a node (1-based line), for error messages.
std::string yaml_where(const std::string& file, const YAML::Node& node);

}  // namespace oscar
