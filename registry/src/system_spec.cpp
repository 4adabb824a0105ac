#include "oscar/registry/system_spec.hpp"

#include <arpa/inet.h>

#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include <fastrtps/config.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oscar/module.hpp"
#include "oscar/security_files.hpp"
#include "oscar/time.hpp"
#include "service_spec.hpp"

namespace oscar {
namespace {

[[noreturn]] void fail(const std::string& at, const std::string& message) {
  throw std::invalid_argument(at + ": " + message);
}

std::chrono::milliseconds millis(const YAML::Node& node, const std::string& file,
                                 const std::string& what) {
  try {
    const auto d = std::chrono::duration_cast<std::chrono::milliseconds>(
        parse_duration(node.as<std::string>()));
    if (d.count() <= 0) throw std::invalid_argument("must be positive");
    return d;
  } catch (const std::exception& e) {
    fail(yaml_where(file, node), fmt::format("{}: {}", what, e.what()));
  }
}

HostSpec parse_host(const std::string& name, const YAML::Node& node, const std::string& file) {
  HostSpec h;
  h.name = name;
  h.where = yaml_where(file, node);
  const auto what = "hosts." + name;
  if (!node.IsMap()) fail(h.where, what + ": expected {local: true} | {netns: NAME} | {ssh: U@H}");
  check_yaml_keys(node, file, what, {"local", "netns", "ssh", "address", "ssh_options", "on_lost"});
  const int kinds = (node["local"] ? 1 : 0) + (node["netns"] ? 1 : 0) + (node["ssh"] ? 1 : 0);
  if (kinds != 1) fail(h.where, what + ": give exactly one of local, netns, ssh");
  if (node["netns"]) {
    h.kind = HostSpec::Kind::kNetns;
    h.netns = node["netns"].as<std::string>();
  } else if (node["ssh"]) {
    h.kind = HostSpec::Kind::kSsh;
    h.ssh = node["ssh"].as<std::string>();
    if (h.ssh.find_first_of(" ;&|'\"$`") != std::string::npos) {
      fail(h.where,
           fmt::format("{}.ssh '{}': expected user@host without shell characters", what, h.ssh));
    }
  } else if (!node["local"].as<bool>()) {
    fail(h.where, what + ": local must be true (or use netns/ssh)");
  }
  if (const auto options = node["ssh_options"]) {
    if (h.kind != HostSpec::Kind::kSsh) fail(h.where, what + ": ssh_options go with ssh");
    if (!options.IsSequence()) {
      fail(yaml_where(file, options), what + ".ssh_options: a list of Key=Value");
    }
    for (const auto& o : options) {
      const auto text = o.IsScalar() ? o.Scalar() : std::string();
      const auto eq = text.find('=');
      if (eq == 0 || eq == std::string::npos || text.find_first_of(" \t\n") < eq) {
        fail(yaml_where(file, o),
             fmt::format("{}.ssh_options '{}': expected Key=Value as after ssh -o (e.g. "
                         "Port=2222)",
                         what, text));
      }
      h.ssh_options.push_back(text);
    }
  }
  if (node["address"]) {
    h.address = node["address"].as<std::string>();
    in_addr a{};
    if (inet_pton(AF_INET, h.address.c_str(), &a) != 1) {
      fail(yaml_where(file, node["address"]),
           fmt::format("{}.address '{}' is not an IPv4 address", what, h.address));
    }
  }
  if (const auto on_lost = node["on_lost"]) {
    const auto policy = on_lost.IsScalar() ? on_lost.Scalar() : std::string();
    if (policy != "suspend" && policy != "continue") {
      fail(yaml_where(file, on_lost),
           fmt::format("{}.on_lost '{}': expected suspend (the system waits for the host) or "
                       "continue (the rest runs on without its modules)",
                       what, policy));
    }
    h.continue_when_lost = policy == "continue";
  }
  // Without an address the remote host's processes would use loopback and never meet the rest.
  if (h.kind == HostSpec::Kind::kSsh && h.address.empty()) {
    fail(h.where, fmt::format("{}: an ssh host needs address: (the IPv4 address DDS uses "
                              "there: {{ssh: {}, address: <that host's IPv4 address>}})",
                              what, h.ssh));
  }
  return h;
}

RestartPolicy parse_restart(const YAML::Node& node, const std::string& file,
                            const std::string& what) {
  RestartPolicy r;
  if (!node) return r;
  if (!node.IsMap()) fail(yaml_where(file, node), what + ": expected a map with policy");
  check_yaml_keys(node, file, what, {"policy", "max", "window", "backoff", "replace", "on_limit"});
  const auto policy =
      node["policy"] ? node["policy"].as<std::string>() : (node["replace"] ? "replace" : "auto");
  if (policy == "auto") {
    r.kind = RestartPolicy::Kind::kAuto;
  } else if (policy == "manual") {
    r.kind = RestartPolicy::Kind::kManual;
  } else if (policy == "replace") {
    r.kind = RestartPolicy::Kind::kReplace;
    if (!node["replace"]) fail(yaml_where(file, node), what + ": policy replace needs replace: M");
    r.replacement = node["replace"].as<std::string>();
  } else {
    fail(yaml_where(file, node["policy"]),
         fmt::format("{}.policy '{}': expected auto, manual or replace", what, policy));
  }
  if (node["replace"] && r.kind != RestartPolicy::Kind::kReplace) {
    fail(yaml_where(file, node["replace"]), what + ": replace goes with policy replace");
  }
  if (node["max"]) {
    r.max = node["max"].as<int>();
    if (r.max < 0) fail(yaml_where(file, node["max"]), what + ".max must be >= 0");
  }
  if (node["window"]) r.window = millis(node["window"], file, what + ".window");
  if (node["backoff"]) r.backoff = millis(node["backoff"], file, what + ".backoff");
  if (node["on_limit"]) {
    const auto on_limit = node["on_limit"].as<std::string>();
    if (on_limit != "suspend" && on_limit != "continue") {
      fail(yaml_where(file, node["on_limit"]),
           fmt::format("{}.on_limit '{}': expected suspend or continue", what, on_limit));
    }
    r.continue_on_limit = on_limit == "continue";
  }
  return r;
}

DebugSpec parse_debug(const YAML::Node& node, const std::string& file, const std::string& what) {
  DebugSpec d;
  if (!node) return d;
  if (!node.IsMap())
    fail(yaml_where(file, node), what +
                                     ": expected {gdbserver: PORT} or "
                                     "{valgrind: [ARGS...]}");
  check_yaml_keys(node, file, what, {"gdbserver", "valgrind"});
  if (node["gdbserver"]) {
    d.gdbserver_port = node["gdbserver"].as<int>();
    if (d.gdbserver_port <= 0 || d.gdbserver_port > 65535) {
      fail(yaml_where(file, node["gdbserver"]), what + ".gdbserver: a TCP port 1..65535");
    }
  }
  if (const auto v = node["valgrind"]) {
    d.valgrind = !(v.IsScalar() && v.Scalar() == "false");
    if (v.IsSequence()) {
      for (const auto& a : v) d.valgrind_args.push_back(a.as<std::string>());
    }
  }
  if (d.valgrind && d.gdbserver_port) fail(yaml_where(file, node), what + ": one debugger only");
  return d;
}

SecuritySpec parse_security(const YAML::Node& node, const std::string& file) {
  SecuritySpec sec;
  sec.where = yaml_where(file, node);
  if (!node.IsMap()) {
    fail(sec.where, "security: expected {keystore: DIR, cue_protection: none|sign|encrypt}");
  }
  check_yaml_keys(node, file, "security", {"keystore", "cue_protection"});
  if (const auto k = node["keystore"]) {
    if (!k.IsScalar() || k.Scalar().empty()) {
      fail(yaml_where(file, k), "security.keystore: expected a folder");
    }
    std::filesystem::path dir = k.Scalar();
    if (dir.is_relative()) dir = std::filesystem::absolute(file).parent_path() / dir;
    sec.keystore = dir.lexically_normal().string();
  }
  if (const auto p = node["cue_protection"]) {
    const auto text = p.IsScalar() ? p.Scalar() : std::string();
    if (text == "none") {
      sec.cue_protection = SecuritySpec::CueProtection::kNone;
    } else if (text == "sign") {
      sec.cue_protection = SecuritySpec::CueProtection::kSign;
    } else if (text == "encrypt") {
      sec.cue_protection = SecuritySpec::CueProtection::kEncrypt;
    } else {
      fail(yaml_where(file, p),
           fmt::format("security.cue_protection '{}': expected none, sign or encrypt", text));
    }
  }
  return sec;
}

// `zero_copy: true|false` or `zero_copy: {chunks: N}`.
std::optional<ZeroCopySpec> parse_zero_copy(const YAML::Node& node, const std::string& file) {
  ZeroCopySpec z;
  z.where = yaml_where(file, node);
  constexpr auto kForm =
      "zero_copy: expected true, false or {chunks: N} (N chunks of each plain cue type, 1..4096)";
  if (node.IsScalar()) {
    bool on = false;
    if (!YAML::convert<bool>::decode(node, on)) fail(z.where, kForm);
    return on ? std::optional(z) : std::nullopt;
  }
  if (!node.IsMap()) fail(z.where, kForm);
  check_yaml_keys(node, file, "zero_copy", {"chunks"});
  if (const auto c = node["chunks"]) {
    long long n = 0;
    if (!c.IsScalar() || !YAML::convert<long long>::decode(c, n) || n < 1 || n > 4096)
      fail(yaml_where(file, c), kForm);
    z.chunks = static_cast<std::uint32_t>(n);
  }
  return z;
}

// A replace chain must end at a standby module and never come back to where it started.
void check_replace_chains(const SystemSpec& s) {
  for (const auto& m : s.modules) {
    std::vector<std::string> chain{m.spec.name};
    const SystemModule* at = &m;
    while (at->restart.kind == RestartPolicy::Kind::kReplace) {
      const auto& next = at->restart.replacement;
      const auto* target = s.find_module(next);
      if (!target) {
        fail(at->spec.where,
             fmt::format("module '{}': replace names no module '{}'", at->spec.name, next));
      }
      if (!target->standby) {
        fail(at->spec.where,
             fmt::format("module '{}': its replacement '{}' must be declared standby: true",
                         at->spec.name, next));
      }
      if (std::find(chain.begin(), chain.end(), next) != chain.end()) {
        chain.push_back(next);
        fail(m.spec.where, fmt::format("cyclic replace chain: {}", fmt::join(chain, " -> ")));
      }
      chain.push_back(next);
      at = target;
    }
  }
}

// The coordinator runs as a module of its own (oscar-coordinator), so the registry supervises
// and restarts it like any other.
void add_coordinator_module(SystemSpec& s, const YAML::Node& node,
                            const std::vector<std::string>& plugins) {
  const auto& c = *s.coordinator;
  if (s.find_module(SystemSpec::kCoordinatorModule)) {
    fail(c.where, fmt::format("a module is named '{}': the name belongs to the process of the "
                              "coordinator: section",
                              SystemSpec::kCoordinatorModule));
  }
  YAML::Node module;
  module["name"] = SystemSpec::kCoordinatorModule;
  module["host"] = c.host;
  YAML::Node kernel;
  kernel["type"] = "coordinator";
  kernel["name"] = SystemSpec::kCoordinatorModule;
  module["kernels"].push_back(kernel);
  module["mode"] = "single_step";  // never triggered; a deactivated kernel takes no commands
  SystemModule m;
  m.spec = ModuleSpec::from_yaml(module, s.file);
  m.spec.where = c.where;
  m.spec.domain = s.domain;
  m.spec.network = NetworkConfig::for_host(s.root, c.host);
  m.spec.lease = s.lease;
  m.spec.plugins = plugins;
  m.restart = parse_restart(node["restart"], s.file, "coordinator.restart");
  m.program = "oscar-coordinator";
  s.modules.push_back(std::move(m));
}

// Each process of applets (an applet's `process:`) runs as a module of its own (oscar-applet),
// supervised and restarted by the registry like any other; its kernel, named after it, only
// keeps the module frame (announcement, heartbeat) going.
void add_applet_modules(SystemSpec& s, const std::vector<std::string>& plugins) {
  std::set<std::string> kernels;
  for (const auto& m : s.modules) {
    for (const auto& k : m.spec.kernels) kernels.insert(k.name);
  }
  for (const auto& a : s.coordinator->applets) {
    if (!a.remote() || s.find_module(a.process)) continue;
    if (kernels.contains(a.process)) {
      fail(a.where, fmt::format("applet '{}'.process: '{}' is a kernel's name; the process's "
                                "module and kernel take that name, name it differently",
                                a.name, a.process));
    }
    YAML::Node module;
    module["name"] = a.process;
    module["host"] = a.host;
    YAML::Node kernel;
    kernel["type"] = "applet_host";
    kernel["name"] = a.process;
    module["kernels"].push_back(kernel);
    module["mode"] = "single_step";  // never triggered
    SystemModule m;
    m.spec = ModuleSpec::from_yaml(module, s.file);
    m.spec.where = a.where;
    m.spec.domain = s.domain;
    m.spec.network = NetworkConfig::for_host(s.root, a.host);
    m.spec.lease = s.lease;
    m.spec.plugins = plugins;
    m.program = "oscar-applet";
    s.modules.push_back(std::move(m));
  }
}

}  // namespace

const char* to_string(SecuritySpec::CueProtection protection) {
  switch (protection) {
    case SecuritySpec::CueProtection::kNone:
      return "none";
    case SecuritySpec::CueProtection::kSign:
      return "sign";
    case SecuritySpec::CueProtection::kEncrypt:
      return "encrypt";
  }
  return "?";
}

std::string DebugSpec::describe() const {
  if (gdbserver_port > 0) return fmt::format("gdbserver 127.0.0.1:{}", gdbserver_port);
  return valgrind ? "valgrind" : "";
}

SystemSpec SystemSpec::load(const std::string& path) { return parse(load_yaml_file(path), path); }

SystemSpec SystemSpec::parse(const YAML::Node& root, const std::string& file) {
  SystemSpec s;
  s.file = file;
  s.root = root;
  if (!root.IsMap()) fail(file, "a system file is a map with system, hosts and modules");
  check_yaml_keys(root, file, "system file",
                  {"system", "domain", "hosts", "modules", "network", "lease", "headless_limit",
                   "plugins", "services", "coordinator", "security", "zero_copy"});
  const auto plugins = ModuleSpec::plugins_of(root, file);
  s.name = root["system"] ? root["system"].as<std::string>() : "system";
  if (root["domain"]) {
    s.domain = root["domain"].as<int>();
    if (s.domain < 0 || s.domain > 232) fail(yaml_where(file, root["domain"]), "domain: 0..232");
  }
  if (root["lease"]) s.lease = millis(root["lease"], file, "lease");
  if (const auto limit = root["headless_limit"]) {
    const bool none = limit.IsScalar() && limit.Scalar() == "none";
    s.headless_limit =
        none ? std::nullopt : std::optional(millis(limit, file, "headless_limit (or none)"));
  }
  if (root["security"]) s.security = parse_security(root["security"], file);
  if (root["zero_copy"]) s.zero_copy = parse_zero_copy(root["zero_copy"], file);
  if (const auto hosts = root["hosts"]) {
    if (!hosts.IsMap() || hosts.size() == 0) fail(yaml_where(file, hosts), "hosts: a map");
    for (const auto& kv : hosts) {
      s.hosts.push_back(parse_host(kv.first.as<std::string>(), kv.second, file));
    }
  } else {
    s.hosts.push_back(HostSpec{"localhost", HostSpec::Kind::kLocal, "", "", "", file, {}});
  }
  const auto modules = root["modules"];
  if (!modules || !modules.IsSequence() || modules.size() == 0) {
    fail(file, "modules: a non-empty list");
  }
  std::map<std::string, std::string> kernels;  // kernel -> module
  for (const auto& node : modules) {
    SystemModule m;
    m.spec = ModuleSpec::from_yaml(node, file);
    const auto what = "module '" + m.spec.name + "'";
    if (s.find_module(m.spec.name)) {
      fail(m.spec.where, fmt::format("duplicate module name '{}'", m.spec.name));
    }
    if (m.spec.host.empty()) {
      if (s.hosts.size() != 1) fail(m.spec.where, what + ": name its host (several are declared)");
      m.spec.host = s.hosts.front().name;
    }
    const bool known = std::any_of(s.hosts.begin(), s.hosts.end(),
                                   [&](const HostSpec& h) { return h.name == m.spec.host; });
    if (!known) {
      std::vector<std::string> names;
      for (const auto& h : s.hosts) names.push_back(h.name);
      fail(yaml_where(file, node["host"]), fmt::format("{}: unknown host '{}' (hosts: {})", what,
                                                       m.spec.host, fmt::join(names, ", ")));
    }
    if (!m.spec.domain) m.spec.domain = s.domain;
    if (!node["network"]) m.spec.network = NetworkConfig::for_host(root, m.spec.host);
    m.spec.lease = s.lease;
    m.spec.plugins.insert(m.spec.plugins.begin(), plugins.begin(), plugins.end());
    m.restart = parse_restart(node["restart"], file, what + ".restart");
    m.debug = parse_debug(node["debug"], file, what + ".debug");
    m.standby = node["standby"] && node["standby"].as<bool>();
    for (const auto& k : m.spec.kernels) {
      const auto [it, added] = kernels.emplace(k.name, m.spec.name);
      if (!added) {
        fail(k.where, fmt::format("duplicate kernel name '{}' (also in module '{}'); kernel "
                                  "names are unique within a system",
                                  k.name, it->second));
      }
    }
    s.modules.push_back(std::move(m));
  }
  for (const auto& m : s.modules) {
    for (const auto& k : m.spec.kernels) {
      for (const auto& [input, wiring] : k.inputs) {
        const auto producer = wiring.source.substr(0, wiring.source.find('/'));
        if (!wiring.source.empty() && !kernels.contains(producer)) {
          fail(k.where, fmt::format("kernel '{}' input '{}': no kernel '{}' in the system", k.name,
                                    input, producer));
        }
      }
    }
  }
  check_replace_chains(s);
  internal::parse_services(s, root["services"]);
  internal::parse_coordinator(s, root["coordinator"]);
  if (s.coordinator) {
    add_coordinator_module(s, root["coordinator"], plugins);
    add_applet_modules(s, plugins);
  }
  std::vector<std::string> names;
  for (const auto& m : s.modules) names.push_back(m.spec.name);
  const auto keystore = s.keystore();
  if (!keystore.empty() && NetworkConfig::for_host(root, "").discovery == Discovery::kServer) {
    // Authentication changes a participant's GUID prefix, so clients no longer find a server at
    // the one they are told; Fast DDS 2.10 made discovery servers work with security.
    fail(yaml_where(file, root["network"]["discovery"]),
         fmt::format("network.discovery: server cannot run with DDS Security (keystore {}): "
                     "Fast DDS {}.{} has no authenticated discovery server; use discovery: static",
                     keystore, FASTRTPS_VERSION_MAJOR, FASTRTPS_VERSION_MINOR));
  }
  for (auto& m : s.modules) {
    m.spec.system_modules = names;
    if (!keystore.empty()) {
      m.spec.network.security =
          ParticipantSecurity{keystore, security_files::module_identity(m.spec.name)};
    }
  }
  return s;
}

std::string SystemSpec::keystore() const { return security_files::system_keystore(root, file); }

NetworkConfig SystemSpec::network_for(const std::string& host_name,
                                      const std::string& identity) const {
  auto network = NetworkConfig::for_host(root, host_name);
  if (const auto k = keystore(); !k.empty()) network.security = ParticipantSecurity{k, identity};
  return network;
}

void SystemSpec::check_modules(const std::vector<std::string>& plugin_path) const {
  std::vector<std::unique_ptr<Module>> built;
  std::map<std::string, const OutputPort*> outputs;  // by "<kernel>/<channel>"
  for (const auto& m : modules) {
    if (m.program != "oscar-run") {
      built.push_back(nullptr);  // the coordinator's kernel is linked into its program
      continue;
    }
    built.push_back(std::make_unique<Module>(m.spec, plugin_path));
    for (const auto& k : m.spec.kernels) {
      for (const auto& out : built.back()->kernel(k.name).ports().outputs) {
        outputs[out->address()] = out.get();
      }
    }
  }
  for (std::size_t i = 0; i < modules.size(); ++i) {
    if (!built[i]) continue;
    for (const auto& k : modules[i].spec.kernels) {
      for (const auto& [input, wiring] : k.inputs) {
        if (wiring.source.empty()) continue;
        const auto* port = built[i]->kernel(k.name).ports().find_input(input);
        const auto it = outputs.find(wiring.source);
        if (it == outputs.end()) {
          fail(k.where, fmt::format("kernel '{}' input '{}': kernel '{}' has no output '{}'",
                                    k.name, input, wiring.source.substr(0, wiring.source.find('/')),
                                    wiring.source.substr(wiring.source.find('/') + 1)));
        }
        const auto& output = *it->second;
        if (port) {
          try {
            check_types(*port, wiring.source, output.type());  // a raw input takes any type
          } catch (const std::invalid_argument& e) {
            fail(k.where, e.what());
          }
        }
        // A pull asks over its own reliable topics; only a push reads the output's writer.
        if (port && port->transfer() == Transfer::kPush) {
          try {
            check_reliability(*port, wiring.source, output.options());
          } catch (const std::invalid_argument& e) {
            fail(k.where, e.what());
          }
        }
      }
    }
  }
}

void SystemSpec::override_domain(int d) {
  domain = d;
  for (auto& m : modules) m.spec.domain = d;
}

const HostSpec& SystemSpec::local_host() const {
  for (const auto& h : hosts) {
    if (h.kind == HostSpec::Kind::kLocal) return h;
  }
  throw std::invalid_argument(
      fmt::format("{}: no host is local: true (boot and the registry run there)", file));
}

const HostSpec& SystemSpec::host(const std::string& host_name) const {
  for (const auto& h : hosts) {
    if (h.name == host_name) return h;
  }
  throw std::invalid_argument(fmt::format("{}: no host '{}'", file, host_name));
}

const ServiceSpec* SystemSpec::find_service(const std::string& service_name) const {
  for (const auto& x : services) {
    if (x.name == service_name) return &x;
  }
  return nullptr;
}

const SystemModule* SystemSpec::find_module(const std::string& module_name) const {
  for (const auto& m : modules) {
    if (m.spec.name == module_name) return &m;
  }
  return nullptr;
}

}  // namespace oscar
