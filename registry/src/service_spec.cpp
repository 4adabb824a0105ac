#include "service_spec.hpp"

#include <algorithm>
#include <cctype>
#include <functional>
#include <map>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oscar/time.hpp"

namespace oscar::internal {
namespace {

[[noreturn]] void fail(const std::string& file, const YAML::Node& node, const std::string& m) {
  throw std::invalid_argument(yaml_where(file, node) + ": " + m);
}

std::string text(const std::string& file, const YAML::Node& node, const std::string& what) {
  if (!node || !node.IsScalar()) fail(file, node, what + " must be a text value");
  return node.as<std::string>();
}

// A scalar or a map where a list belongs would read as an empty list or one item: say so.
// Returns the node by value (a handle): a range-for over a reference to the temporary argument
// would outlive it.
YAML::Node list(const std::string& file, const YAML::Node& node, const std::string& what,
                const char* example) {
  if (!node.IsSequence())
    fail(file, node, fmt::format("{} must be a list, such as {}", what, example));
  return node;
}

ServiceSpec::Provider provider_of(const SystemSpec& s, const YAML::Node& node,
                                  const std::string& what) {
  const auto t = text(s.file, node, what + " entry");
  const auto slash = t.find('/');
  ServiceSpec::Provider p;
  p.module = t.substr(0, slash);
  p.kernel = slash == std::string::npos ? "" : t.substr(slash + 1);
  const auto* m = s.find_module(p.module);
  if (!m) {
    std::vector<std::string> names;
    for (const auto& x : s.modules) names.push_back(x.spec.name);
    fail(s.file, node,
         fmt::format("{}: no module '{}' in the system (modules: {})", what, p.module,
                     fmt::join(names, ", ")));
  }
  if (!p.kernel.empty() && !m->spec.find_kernel(p.kernel)) {
    fail(s.file, node, fmt::format("{}: module '{}' has no kernel '{}'", what, p.module, p.kernel));
  }
  p.param_kernel = !p.kernel.empty()             ? p.kernel
                   : m->spec.kernels.size() == 1 ? m->spec.kernels.front().name
                                                 : "";
  return p;
}

// `set: {name: value}`: parameters as text, in file order.
ServiceSpec::Params parse_params(const std::string& file, const YAML::Node& node,
                                 const std::string& what) {
  if (!node.IsMap() || node.size() == 0) {
    fail(file, node, what + ": expected a map of parameters such as {frame_mode: half}");
  }
  ServiceSpec::Params params;
  for (const auto& kv : node) {
    params.emplace_back(kv.first.as<std::string>(),
                        text(file, kv.second, what + "." + kv.first.as<std::string>()));
  }
  return params;
}

void parse_granted(ServiceSpec& svc, const std::string& file, const YAML::Node& node,
                   const std::string& what) {
  if (node.IsScalar() && node.Scalar() == "nothing") return;
  if (node.IsScalar() && node.Scalar() == "activate") {
    svc.activate = "";
    return;
  }
  if (!node.IsMap()) {
    fail(file, node, what + ": expected {activate: MODE, set: {...}}, activate or nothing");
  }
  check_yaml_keys(node, file, what, {"activate", "set"});
  if (!node["activate"] && !node["set"]) {
    fail(file, node, what + ": expected {activate: MODE} and/or {set: {param: value}}");
  }
  if (node["set"]) svc.granted_params = parse_params(file, node["set"], what + ".set");
  if (!node["activate"]) return;
  const auto mode = text(file, node["activate"], what + ".activate");
  try {
    if (ModeSpec::parse_text(mode).kind == ModeSpec::Kind::kDeactivated) {
      throw std::invalid_argument("a granted service's modules cannot be activated deactivated");
    }
  } catch (const std::invalid_argument& e) {
    fail(file, node["activate"], fmt::format("{}.activate: {}", what, e.what()));
  }
  svc.activate = mode;
}

void parse_idle(ServiceSpec& svc, const std::string& file, const YAML::Node& node,
                const std::string& what) {
  if (node.IsMap()) {
    check_yaml_keys(node, file, what, {"set"});
    if (!node["set"]) fail(file, node, what + ": expected {set: {param: value}}");
    svc.idle_params = parse_params(file, node["set"], what + ".set");
    return;
  }
  const auto idle = text(file, node, what);
  if (idle != "deactivate" && idle != "keep") {
    fail(
        file, node,
        fmt::format("{} '{}': expected deactivate, keep or {{set: {{param: value}}}}", what, idle));
  }
  svc.idle_deactivates = idle == "deactivate";
}

// Parameters belong to a kernel: a provider named by its module alone must have only one.
void check_param_providers(const SystemSpec& s, const ServiceSpec& svc, const YAML::Node& node,
                           const std::string& what) {
  if (svc.granted_params.empty() && svc.idle_params.empty()) return;
  for (const auto& p : svc.providers) {
    if (!p.kernel.empty()) continue;
    const auto& kernels = s.find_module(p.module)->spec.kernels;
    if (kernels.size() != 1) {
      fail(s.file, node,
           fmt::format("{}: set: parameters belong to one kernel, but provider '{}' has {} "
                       "kernels; name the kernel in provided_by ({}/{})",
                       what, p.module, kernels.size(), p.module, kernels.front().name));
    }
  }
}

// A cycle of services needing each other can never be granted: no applet can break it.
void check_cycles(const SystemSpec& s) {
  std::map<std::string, int> state;  // 0 new, 1 on the path, 2 done
  std::vector<std::string> path;
  std::function<void(const ServiceSpec&)> visit = [&](const ServiceSpec& svc) {
    state[svc.name] = 1;
    path.push_back(svc.name);
    for (const auto& n : svc.needs) {
      if (state[n.service] == 1) {
        path.push_back(n.service);
        const auto start = std::find(path.begin(), path.end(), n.service);
        const auto& first = *s.find_service(n.service);
        throw std::invalid_argument(fmt::format(
            "{}: service '{}': a cycle of needs: {} (services that need each other can never be "
            "granted)",
            first.where, first.name,
            fmt::join(std::vector<std::string>(start, path.end()), " -> ")));
      }
      if (state[n.service] == 0) visit(*s.find_service(n.service));
    }
    path.pop_back();
    state[svc.name] = 2;
  };
  for (const auto& svc : s.services) {
    if (state[svc.name] == 0) visit(svc);
  }
}

// A service is provided by modules (provided_by) or by one applet (its provides:, seed 000
// §4.2.3: the UI service of §5.3 is the UIService applet's), never by both or by nobody.
void check_service_providers(const SystemSpec& s, const std::vector<AppletSpec>& applets,
                             std::size_t first_service = 0) {
  std::map<std::string, std::string> by_applet;  // service -> applet
  for (const auto& a : applets) {
    const auto provides = a.node["provides"];
    if (!provides) continue;
    for (const auto& p : list(s.file, provides, "applet '" + a.name + "'.provides", "[UI]")) {
      const auto service = text(s.file, p, "applet '" + a.name + "'.provides entry");
      const auto* svc = s.find_service(service);
      if (!svc) {
        fail(s.file, p,
             fmt::format("applet '{}' provides service '{}', which is not declared under "
                         "services:",
                         a.name, service));
      }
      if (!svc->providers.empty()) {
        fail(s.file, p,
             fmt::format("applet '{}' provides service '{}', which modules provide already "
                         "(provided_by at {}): a service has one kind of provider",
                         a.name, service, svc->where));
      }
      if (const auto [it, fresh] = by_applet.emplace(service, a.name); !fresh) {
        fail(s.file, p,
             fmt::format("service '{}' is provided by two applets, '{}' and '{}'", service,
                         it->second, a.name));
      }
    }
  }
  for (std::size_t i = first_service; i < s.services.size(); ++i) {
    const auto& svc = s.services[i];
    if (svc.providers.empty() && !by_applet.contains(svc.name)) {
      throw std::invalid_argument(fmt::format(
          "{}: service '{}': nobody provides it: name its modules in provided_by, or list it "
          "under an applet's provides:",
          svc.where, svc.name));
    }
  }
}

// `wishes: [{kernel: module/kernel, bundles: [...]}]`: the bundles are the applet scheduler's
// (checked when it reads them); `requested:` is the kernel's to decide.
void parse_wishes(const SystemSpec& s, CoordinatorSpec& c, const YAML::Node& node) {
  for (const auto& w : list(s.file, node, "coordinator.wishes",
                            "[{kernel: door_search/door_search, bundles: [...]}]")) {
    if (!w.IsMap())
      fail(s.file, w, "coordinator.wishes: each entry is a map with kernel and bundles");
    check_yaml_keys(w, s.file, "coordinator.wishes entry", {"kernel", "bundles"});
    const auto who = text(s.file, w["kernel"], "coordinator.wishes entry's kernel");
    const auto slash = who.find('/');
    if (slash == std::string::npos) {
      fail(s.file, w["kernel"],
           fmt::format("coordinator.wishes: kernel '{}' must be module/kernel", who));
    }
    const auto p = provider_of(s, w["kernel"], "coordinator.wishes");
    const auto what = fmt::format("coordinator.wishes '{}'", who);
    if (std::any_of(c.wishes.begin(), c.wishes.end(),
                    [&](const WishSpec& x) { return x.applet() == who; })) {
      fail(s.file, w["kernel"], what + ": the kernel is listed twice; give all its bundles once");
    }
    if (!w["bundles"] || !w["bundles"].IsSequence() || w["bundles"].size() == 0) {
      fail(s.file, w,
           what +
               ": bundles must be a list such as [{name: half_frames, resources: "
               "[{service: HalfFrames}]}]");
    }
    for (const auto& b : w["bundles"]) {
      if (b.IsMap() && b["requested"]) {
        fail(s.file, b["requested"],
             what + ": a wish is asked by its kernel (Wish::ask), not requested at start");
      }
    }
    c.wishes.push_back({p.module, p.kernel, w["bundles"], yaml_where(s.file, w)});
  }
}

}  // namespace

namespace {

// Reads `services:` and appends them to s.services; the services there before are known to
// their needs (and their names are taken).
void append_services(SystemSpec& s, const YAML::Node& node) {
  const std::size_t first = s.services.size();
  if (!node.IsMap()) fail(s.file, node, "services: a map of service names to services");
  for (const auto& kv : node) {
    ServiceSpec svc;
    svc.name = kv.first.as<std::string>();
    svc.where = yaml_where(s.file, kv.first);
    const auto what = "service '" + svc.name + "'";
    const auto& n = kv.second;
    if (!n.IsMap()) fail(s.file, n, what + ": expected a map with provided_by");
    check_yaml_keys(n, s.file, what, {"provided_by", "access", "needs", "granted", "idle"});
    // No provided_by: an applet provides it (checked with the applets, parse_coordinator).
    if (n["provided_by"]) {
      for (const auto& p :
           list(s.file, n["provided_by"], what + ".provided_by", "[cam, marks/mark_a]")) {
        svc.providers.push_back(provider_of(s, p, what + ".provided_by"));
      }
    }
    if (n["access"]) {
      const auto a = text(s.file, n["access"], what + ".access");
      if (a != "shared" && a != "exclusive") {
        fail(s.file, n["access"],
             fmt::format("{}.access '{}': expected shared or exclusive", what, a));
      }
      svc.exclusive_only = a == "exclusive";
    }
    if (n["granted"]) parse_granted(svc, s.file, n["granted"], what + ".granted");
    if (n["idle"]) parse_idle(svc, s.file, n["idle"], what + ".idle");
    check_param_providers(s, svc, n, what);
    if (s.find_service(svc.name)) fail(s.file, kv.first, "duplicate service '" + svc.name + "'");
    s.services.push_back(std::move(svc));
  }
  // Needs in a second pass: their order in the file does not matter.
  for (std::size_t i = first; i < s.services.size(); ++i) {
    auto& svc = s.services[i];
    const auto what = "service '" + svc.name + "'";
    const auto needs = node[svc.name]["needs"];
    if (!needs) continue;
    for (const auto& d : list(s.file, needs, what + ".needs", "[Pilot]")) {
      ServiceSpec::Need need;
      // Not `YAML::Node name = d; name = d["service"];`: assigning to a node that refers to `d`
      // rewrites `d` itself (yaml-cpp nodes are references), and d["access"] then fails.
      if (d.IsMap()) {
        check_yaml_keys(d, s.file, what + ".needs", {"service", "access"});
        if (d["access"]) need.exclusive = text(s.file, d["access"], "access") != "shared";
      }
      const YAML::Node name = d.IsMap() ? d["service"] : d;
      need.service = text(s.file, name, what + ".needs entry");
      if (!s.find_service(need.service)) {
        fail(s.file, name,
             fmt::format("{} needs service '{}', which is not declared under "
                         "services:",
                         what, need.service));
      }
      if (need.service == svc.name) fail(s.file, name, what + " needs itself");
      svc.needs.push_back(need);
    }
  }
  check_cycles(s);
}

bool identifier(const std::string& name) {
  return !name.empty() && !std::isdigit(static_cast<unsigned char>(name[0])) &&
         std::all_of(name.begin(), name.end(), [](char ch) {
           return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
         });
}

// One entry of `applets:`; `coordinator_host` is where a process without a host runs, and
// `process_hosts` (process -> host) keeps a process on one host.
AppletSpec parse_applet(const SystemSpec& s, const YAML::Node& a,
                        const std::string& coordinator_host,
                        std::map<std::string, std::string>& process_hosts) {
  auto known_host = [&](const std::string& h) {
    return std::any_of(s.hosts.begin(), s.hosts.end(),
                       [&](const HostSpec& x) { return x.name == h; });
  };
  if (!a.IsMap()) fail(s.file, a, "coordinator.applets: each applet is a map with type and name");
  check_yaml_keys(
      a, s.file, "applet",
      {"type", "name", "params", "bundles", "fail_stop", "process", "host", "provides"});
  AppletSpec spec{text(s.file, a["type"], "applet type"),
                  text(s.file, a["name"], "applet name"),
                  a,
                  yaml_where(s.file, a),
                  "",
                  ""};
  const auto what = fmt::format("applet '{}'", spec.name);
  if (a["host"]) {
    spec.host = text(s.file, a["host"], what + ".host");
    if (!known_host(spec.host)) {
      std::vector<std::string> names;
      for (const auto& h : s.hosts) names.push_back(h.name);
      fail(s.file, a["host"],
           fmt::format("{}: unknown host '{}' (hosts: {})", what, spec.host,
                       fmt::join(names, ", ")));
    }
  }
  if (a["process"]) {
    spec.process = text(s.file, a["process"], what + ".process");
    if (!identifier(spec.process)) {
      fail(s.file, a["process"],
           fmt::format("{}.process '{}': a process name is a module name, an identifier "
                       "(letters, digits, _)",
                       what, spec.process));
    }
    if (spec.process == SystemSpec::kCoordinatorModule) {
      fail(s.file, a["process"],
           fmt::format("{}.process: '{}' is the coordinator's own process; leave process: "
                       "out to run the applet there",
                       what, spec.process));
    }
    if (s.find_module(spec.process)) {
      fail(s.file, a["process"],
           fmt::format("{}.process: '{}' is a module of the system; an applet process is a "
                       "module of its own, name it differently",
                       what, spec.process));
    }
  } else if (!spec.host.empty()) {
    spec.process = "applets_" + spec.host;
    for (char& ch : spec.process) {
      if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    }
  }
  if (spec.remote()) {
    if (spec.host.empty()) spec.host = coordinator_host;
    const auto [it, added] = process_hosts.emplace(spec.process, spec.host);
    if (!added && it->second != spec.host) {
      fail(s.file, a["host"] ? a["host"] : a["process"],
           fmt::format("{}: process '{}' runs on host '{}' (an applet before says so); a "
                       "process has one host",
                       what, spec.process, it->second));
    }
  }
  return spec;
}

}  // namespace

void parse_services(SystemSpec& s, const YAML::Node& node) {
  if (!node) return;
  append_services(s, node);
}

void parse_coordinator(SystemSpec& s, const YAML::Node& node) {
  if (!node) {
    if (!s.services.empty()) {
      fail(s.file, s.root["services"], "services: need a coordinator: section (who grants them)");
    }
    return;
  }
  if (!node.IsMap()) fail(s.file, node, "coordinator: expected a map with host and applets");
  check_yaml_keys(node, s.file, "coordinator",
                  {"host", "applets", "scheduler", "restart", "applet_lease", "wishes", "swarm"});
  CoordinatorSpec c;
  c.where = yaml_where(s.file, node);
  auto known_host = [&](const std::string& h) {
    return std::any_of(s.hosts.begin(), s.hosts.end(),
                       [&](const HostSpec& x) { return x.name == h; });
  };
  if (node["host"]) {
    c.host = text(s.file, node["host"], "coordinator.host");
    if (!known_host(c.host)) {
      fail(s.file, node["host"], fmt::format("coordinator: unknown host '{}'", c.host));
    }
  } else {
    if (s.hosts.size() != 1)
      fail(s.file, node, "coordinator: name its host (several are declared)");
    c.host = s.hosts.front().name;
  }
  if (node["scheduler"]) c.scheduler = node["scheduler"];
  if (node["swarm"]) c.swarm = node["swarm"];
  if (const auto lease = node["applet_lease"]) {
    try {
      c.applet_lease = std::chrono::duration_cast<std::chrono::milliseconds>(
          parse_duration(text(s.file, lease, "coordinator.applet_lease")));
      if (c.applet_lease.count() <= 0) throw std::invalid_argument("must be positive");
    } catch (const std::exception& e) {
      fail(s.file, lease, fmt::format("coordinator.applet_lease: {}", e.what()));
    }
  }
  std::map<std::string, std::string> process_hosts;  // process -> host
  if (node["applets"]) {
    for (const auto& a :
         list(s.file, node["applets"], "coordinator.applets", "[{type: T, name: N}]")) {
      c.applets.push_back(parse_applet(s, a, c.host, process_hosts));
    }
  }
  if (node["wishes"]) parse_wishes(s, c, node["wishes"]);
  check_service_providers(s, c.applets);
  s.coordinator = std::move(c);
}

}  // namespace oscar::internal

namespace oscar {

SystemAddition SystemSpec::parse_addition(const YAML::Node& addition,
                                          const std::string& addition_file,
                                          const std::vector<ServiceSpec>& services_now) const {
  using internal::fail;
  // The running system as it is now, read from `addition_file`: messages point into the addition.
  SystemSpec now = *this;
  now.file = addition_file;
  now.services = services_now;
  now.root = addition;
  if (!addition || !addition.IsMap()) {
    fail(addition_file, addition, "an addition is a map with services: and/or applets:");
  }
  check_yaml_keys(addition, addition_file, "an addition", {"services", "applets"});
  if (!addition["services"] && !addition["applets"]) {
    fail(addition_file, addition, "an addition names services: or applets: (or both)");
  }
  if (!coordinator)
    fail(addition_file, addition, "the system has no coordinator: section (who grants them)");
  const std::size_t first = now.services.size();
  if (addition["services"]) internal::append_services(now, addition["services"]);
  SystemAddition out;
  std::map<std::string, std::string> process_hosts;
  if (addition["applets"]) {
    for (const auto& a :
         internal::list(addition_file, addition["applets"], "applets", "[{type: T, name: N}]")) {
      out.applets.push_back(internal::parse_applet(now, a, coordinator->host, process_hosts));
    }
  }
  internal::check_service_providers(now, out.applets, first);
  out.services.assign(now.services.begin() + static_cast<std::ptrdiff_t>(first),
                      now.services.end());
  return out;
}

}  // namespace oscar
