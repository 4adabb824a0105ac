#pragma once
/// @file SystemSpec: a system file (docs/boot.md) — hosts, modules with their restart policies and
/// debug wrappers — parsed and checked whole before anything is started.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "oscar/module_spec.hpp"

namespace oscar {

/// Where a host's processes run: here, in a network namespace (a test host), or over ssh.
struct HostSpec {
  enum class Kind { kLocal, kNetns, kSsh };
  std::string name;
  Kind kind = Kind::kLocal;
  std::string netns;    ///< kNetns: the namespace's name
  std::string ssh;      ///< kSsh: "user@host"
  std::string address;  ///< optional IPv4 address DDS uses on that host
  std::string where;    ///< "file:line"
  /// kSsh: ssh client options, each "Key=Value" as after `ssh -o` (Port, IdentityFile, ...).
  std::vector<std::string> ssh_options;
  /// When the host is lost (its monitor's lease lapsed: a cut link, a robot out of range), the
  /// rest of the system resumes without its modules instead of staying suspended until it is back.
  bool continue_when_lost = false;
};

/// What the registry does when the module fails (docs/boot.md).
struct RestartPolicy {
  enum class Kind { kAuto, kManual, kReplace };
  Kind kind = Kind::kAuto;
  int max = 3;  ///< kAuto: restarts within `window` before the module is given up
  /// kAuto: restarts longer ago than this no longer count against `max`.
  std::chrono::milliseconds window{std::chrono::minutes(10)};
  std::chrono::milliseconds backoff{200};  ///< kAuto: wait before each restart
  std::string replacement;                 ///< kReplace: the standby module started instead
  bool continue_on_limit = false;          ///< the rest resumes once the module is given up
};

/// Start the module under a debugger or checker.
struct DebugSpec {
  int gdbserver_port = 0;  ///< >0: gdbserver listening on 127.0.0.1:<port>
  bool valgrind = false;
  std::vector<std::string> valgrind_args;

  /// True under a debugger that holds the process at breakpoints (gdbserver). Such a module's
  /// silent heartbeat is no hang: the registry does not kill it for that (its exit still counts).
  bool holds_process() const { return gdbserver_port > 0; }
  /// What `oscar ps` shows: "gdbserver 127.0.0.1:PORT", "valgrind", or "" when started plainly.
  std::string describe() const;
};

struct SystemModule {
  ModuleSpec spec;
  RestartPolicy restart;
  DebugSpec debug;
  bool standby = false;  ///< started only as another module's replacement
  /// The program the monitor starts: "oscar-run", "oscar-coordinator" for the module the
  /// `coordinator:` section makes, or "oscar-applet" for a process of applets (`process:`).
  std::string program = "oscar-run";
};

/// A service of the applet scheduler and the modules that provide it (docs/coordinator.md).
struct ServiceSpec {
  struct Provider {
    std::string module;
    std::string kernel;  ///< empty: every kernel of the module
    /// The kernel parameters go to (`set:`): `kernel`, or the module's only one.
    std::string param_kernel;
    std::string text() const { return kernel.empty() ? module : module + "/" + kernel; }
  };
  struct Need {
    std::string service;
    bool exclusive = true;
  };
  std::string name;
  std::vector<Provider> providers;
  bool exclusive_only = false;  ///< `access: exclusive`
  std::vector<Need> needs;
  /// `granted: {activate: MODE}`: activate the providers when the service is granted, in MODE
  /// (mode text such as "continuous:33ms"; empty: the kernel's configured mode).
  std::optional<std::string> activate;
  bool idle_deactivates = false;  ///< `idle: deactivate` (else `idle: keep`)
  using Params = std::vector<std::pair<std::string, std::string>>;  ///< name, value (as text)
  /// `granted: {set: {name: value}}`: parameters the providers' kernels get while it is granted.
  Params granted_params;
  /// `idle: {set: {name: value}}`: parameters they get while nobody holds it.
  Params idle_params;
  std::string where;  ///< "file:line"
};

/// One applet the coordinator runs: its type (a registered applet class) and its configuration
/// in the applet scheduler's vocabulary (name, params, bundles, fail_stop), and where it runs.
struct AppletSpec {
  std::string type;
  std::string name;
  YAML::Node node;
  std::string where;
  /// The process it runs in: empty for the coordinator's own; else a process of its own that
  /// boot starts (program oscar-applet, a module of this name) and that talks to the
  /// coordinator over DDS (`process: NAME`, or `host: H` alone: "applets_H").
  std::string process;
  std::string host;  ///< the host of `process` (default: the coordinator's)
  bool remote() const { return !process.empty(); }
};

/// What one kernel may wish from the coordinator (`coordinator: wishes:`, seed 004 §2.4): its
/// bundles in the applet scheduler's vocabulary. The scheduler knows the kernel as the applet
/// "module/kernel", whose bundles are requested and released as the kernel asks and drops them.
struct WishSpec {
  std::string module;
  std::string kernel;
  YAML::Node bundles;
  std::string where;
  std::string applet() const { return module + "/" + kernel; }
};

/// The `coordinator:` section: where the coordinator runs and what it runs.
struct CoordinatorSpec {
  std::string host;
  YAML::Node scheduler;  ///< scheduler options, as the applet scheduler reads them
  YAML::Node swarm;      ///< the live swarm (robots, world, settings), as the coordinator reads it
  std::vector<AppletSpec> applets;
  std::vector<WishSpec> wishes;
  /// How long the coordinator waits for a beat of an applet in another process before it takes
  /// the applet's bundles (`applet_lease:`).
  std::chrono::milliseconds applet_lease{1500};
  std::string where;
};

/// The `security:` section (docs/security.md): where the system's DDS Security keystore lies and
/// how cue data is protected on the wire. Control topics are always protected; cue topics carry
/// the bulk of the traffic, so the system file chooses what their protection may cost.
struct SecuritySpec {
  enum class CueProtection { kNone, kSign, kEncrypt };
  std::string keystore;  ///< absolute (a relative path is taken from the system file's folder)
  CueProtection cue_protection = CueProtection::kNone;
  std::string where;  ///< "file:line"
};
/// "none", "sign", "encrypt".
const char* to_string(SecuritySpec::CueProtection protection);

/// `zero_copy:` (docs/zero_copy.md): each host's monitor keeps an iceoryx RouDi running, which
/// carries the plain cue types between the host's processes without copies.
struct ZeroCopySpec {
  /// Chunks of each plain cue type in a host's RouDi: per type at least its outputs' ring depths
  /// + 2 loans per output + its consumers' ring depths × 2 (ring and queue) on the host
  /// (docs/zero_copy.md, "Limits learned").
  std::uint32_t chunks = 64;
  std::string where;  ///< "file:line"
};

/// Services and applets added to a running system (docs/coordinator.md, "Adding and removing at
/// run time"), as SystemSpec::parse_addition reads them.
struct SystemAddition {
  std::vector<ServiceSpec> services;
  std::vector<AppletSpec> applets;
};

struct SystemSpec {
  std::string file;
  std::string name;
  int domain = 0;
  std::chrono::milliseconds lease{300};
  /// How long a host's monitor lets its modules run without a registry (a network split, or a
  /// registry gone for good) before it stops them in order; nullopt: no limit (`none`).
  std::optional<std::chrono::milliseconds> headless_limit = std::chrono::milliseconds{2000};
  std::vector<HostSpec> hosts;        ///< without a `hosts:` key, one local host "localhost"
  std::vector<SystemModule> modules;  ///< with the coordinator's module, if there is one
  std::vector<ServiceSpec> services;
  std::optional<CoordinatorSpec> coordinator;
  std::optional<SecuritySpec> security;
  std::optional<ZeroCopySpec> zero_copy;  ///< none: cues go serialized through DDS only
  YAML::Node root;

  /// The module name the `coordinator:` section's process announces itself under.
  static constexpr const char* kCoordinatorModule = "coordinator";

  /// Reads and checks a system file: unknown keys, unknown hosts, duplicate module or kernel
  /// names, wiring to unknown kernels, replace chains (unknown, not standby, cyclic).
  /// @throws std::invalid_argument "file:line: ..." naming the thing and the rule.
  static SystemSpec load(const std::string& path);
  static SystemSpec parse(const YAML::Node& root, const std::string& file);

  /// Reads services and applets to add to this running system: `services:` as in the system
  /// file (provided_by names its modules) and `applets:` as entries of `coordinator: applets:`.
  /// `services_now` are the services the system has now (its own and those added since): the
  /// new ones may need them, their names are taken. `addition_file` names the text in messages.
  /// @throws std::invalid_argument "file:line: ..." naming the thing and the rule.
  SystemAddition parse_addition(const YAML::Node& addition, const std::string& addition_file,
                                const std::vector<ServiceSpec>& services_now) const;

  /// Builds every module without DDS (loads the plugins, checks the multi-core rules and the
  /// types of wires between modules, and that no reliable input reads a best-effort output).
  /// @throws std::invalid_argument naming module and rule.
  void check_modules(const std::vector<std::string>& plugin_path) const;

  /// The keystore the system's processes run with: $OSCAR_KEYSTORE (`oscar boot --keystore`),
  /// else `security: keystore:`; "" for a system without DDS Security.
  std::string keystore() const;
  /// The transport profile of a process on `host` that runs as `identity`: the host's
  /// NetworkConfig::for_host, authenticated as `identity` when the system has a keystore.
  NetworkConfig network_for(const std::string& host, const std::string& identity) const;

  /// Every module's domain becomes `domain` (boot --domain, tests).
  void override_domain(int domain);
  /// The host boot and the registry run on: the first `local: true` host.
  /// @throws std::invalid_argument if the system declares none.
  const HostSpec& local_host() const;
  const HostSpec& host(const std::string& name) const;
  const SystemModule* find_module(const std::string& name) const;
  const ServiceSpec* find_service(const std::string& name) const;
};

}  // namespace oscar
