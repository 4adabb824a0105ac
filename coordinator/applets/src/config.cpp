#include "oscar/applets/config.hpp"

#include "yaml_helpers.hpp"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace oscar::applets {

namespace internal {

void fail_at(const YAML::Node& node, const std::string& file, const std::string& m) {
  throw std::invalid_argument(where(node, file) + ": " + m);
}

long long number(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node || !node.IsScalar()) fail_at(node, file, what + " must be a number");
  try {
    return node.as<long long>();
  } catch (const YAML::Exception&) {
    fail_at(node, file, what + " must be a whole number, not '" + node.as<std::string>() + "'");
  }
}

bool flag(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node) return false;
  if (node.IsScalar()) {
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
    }
  }
  fail_at(node, file, what + " must be true or false");
}

}  // namespace internal

namespace {

using internal::fail_at;
using internal::flag;
using internal::number;

void allow_keys(const YAML::Node& node, const std::string& file, const std::string& what,
                const std::set<std::string>& keys) {
  if (!node.IsMap()) fail_at(node, file, what + " must be a mapping");
  for (const auto& kv : node) {
    const auto key = kv.first.as<std::string>();
    if (!keys.count(key)) {
      std::string list;
      for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
      fail_at(kv.first, file, what + ": unknown key '" + key + "' (allowed: " + list + ")");
    }
  }
}

std::string text(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node || !node.IsScalar()) fail_at(node, file, what + " must be a text value");
  return node.as<std::string>();
}

Access access_of(const YAML::Node& node, const std::string& file) {
  const std::string a = text(node, file, "access");
  if (a == "exclusive") return Access::kExclusive;
  if (a == "shared") return Access::kShared;
  fail_at(node, file, "access '" + a + "' must be 'shared' or 'exclusive'");
}

ServiceId service_at(const Model& model, const YAML::Node& node, const std::string& file,
                     const std::string& who) {
  const std::string name = text(node, file, "service");
  if (auto id = model.find_service(name)) return *id;
  fail_at(node, file, who + ": unknown service '" + name + "' (declare it under services:)");
}

std::map<std::string, std::string> params_of(const YAML::Node& node, const std::string& file) {
  std::map<std::string, std::string> out;
  if (!node) return out;
  if (!node.IsMap()) fail_at(node, file, "params must be a mapping of names to values");
  for (const auto& kv : node) {
    out[kv.first.as<std::string>()] =
        kv.second.IsScalar() ? kv.second.as<std::string>() : YAML::Dump(kv.second);
  }
  return out;
}

}  // namespace

namespace {

// Reads `services:` (a list) into `model`; returns the ids it added.
std::vector<ServiceId> read_services(Model& model, const YAML::Node& services,
                                     const std::string& file, SystemConfig& c) {
  std::vector<ServiceId> added;
  for (const auto& s : services) {
    allow_keys(s, file, "service", {"name", "exclusive_only", "depends_on", "params"});
    const std::string name = text(s["name"], file, "service name");
    const bool exclusive_only = flag(s["exclusive_only"], file, "exclusive_only");
    try {
      added.push_back(model.add_service(name, exclusive_only));
    } catch (const std::invalid_argument& e) {
      fail_at(s["name"], file, e.what());
    }
    c.service_params[name] = params_of(s["params"], file);
  }
  // Dependencies in a second pass so that their order in the file does not matter.
  for (const auto& s : services) {
    const YAML::Node deps = s["depends_on"];
    if (!deps) continue;
    const std::string name = s["name"].as<std::string>();
    if (!deps.IsSequence())
      fail_at(deps, file, "service '" + name + "': depends_on must be a list");
    for (const auto& d : deps) {
      // Not `YAML::Node svc = d; svc = d["service"];`: assigning to a node that refers to `d`
      // rewrites `d` itself (yaml-cpp nodes are references), and d["access"] then fails.
      if (d.IsMap()) allow_keys(d, file, "dependency", {"service", "access"});
      const YAML::Node svc = d.IsMap() ? d["service"] : d;
      const Access access =
          d.IsMap() && d["access"] ? access_of(d["access"], file) : Access::kExclusive;
      const std::string dep = text(svc, file, "dependency");
      const auto id = model.find_service(dep);
      if (!id) {
        fail_at(svc, file, "service '" + name + "' depends on unknown service '" + dep + "'");
      }
      try {
        model.add_dependency(model.service_id(name), *id, access);
      } catch (const std::invalid_argument& e) {
        fail_at(svc, file, e.what());
      }
    }
  }
  return added;
}

// A bundle's `deadline: {early_ms, duration_ms, finish_ms}`, counted from each request; checked
// with the context switch (eq. 4.9) here, with its line, rather than at the request.
void set_request_deadline(Model& model, const SchedulerOptions& options, BundleId bundle,
                          const YAML::Node& node, const std::string& file, const std::string& who) {
  if (!node.IsMap()) {
    fail_at(node, file,
            who +
                ": deadline must be a map such as {early_ms: 0, duration_ms: 500, "
                "finish_ms: 2000} (counted from each request)");
  }
  allow_keys(node, file, "deadline", {"early_ms", "duration_ms", "finish_ms"});
  if (!node["finish_ms"]) fail_at(node, file, who + ": deadline needs finish_ms");
  auto ms_of = [&](const char* key) {
    return node[key] ? milliseconds{number(node[key], file, key)} : milliseconds{0};
  };
  Deadline d{ms_of("early_ms"), ms_of("duration_ms"), ms_of("finish_ms")};
  try {
    if (d.t_early + d.t_duration + options.context_switch > d.t_finish) {
      throw std::invalid_argument(
          who +
          ": deadline needs early_ms + duration_ms + context_switch_ms <= finish_ms (eq. 4.9), "
          "but " +
          std::to_string(d.t_early.count()) + " + " + std::to_string(d.t_duration.count()) + " + " +
          std::to_string(options.context_switch.count()) + " > " +
          std::to_string(d.t_finish.count()));
    }
    model.set_request_deadline(bundle, d);
  } catch (const std::invalid_argument& e) {
    fail_at(node, file, e.what());
  }
}

// Reads `applets:` (a list) into `model`; returns the ids it added. Bundles with
// `requested: true` go to c.requested_at_start, their nodes to `requested_at`.
std::vector<AppletId> read_applets(Model& model, const YAML::Node& applets, const std::string& file,
                                   SystemConfig& c, std::vector<YAML::Node>& requested_at) {
  std::vector<AppletId> added;
  if (applets && !applets.IsSequence()) fail_at(applets, file, "'applets' must be a list");
  for (const auto& a : applets) {
    allow_keys(a, file, "applet", {"name", "provides", "bundles", "params", "fail_stop"});
    const std::string name = text(a["name"], file, "applet name");
    AppletId id = 0;
    const bool fail_stop = flag(a["fail_stop"], file, "fail_stop");
    try {
      id = model.add_applet(name, fail_stop);
    } catch (const std::invalid_argument& e) {
      fail_at(a["name"], file, e.what());
    }
    added.push_back(id);
    c.applet_params[name] = params_of(a["params"], file);
    // A scalar or a mapping where a list belongs would be read as an empty list: say so.
    for (const char* key : {"provides", "bundles"}) {
      if (a[key] && !a[key].IsSequence()) {
        fail_at(a[key], file,
                "applet '" + name + "': " + key + " must be a list" +
                    (std::string(key) == "provides" ? " of services, such as [UI]"
                                                    : " of bundles, such as [{name: b, ...}]"));
      }
    }
    for (const auto& p : a["provides"]) {
      try {
        model.provide(id, service_at(model, p, file, "applet '" + name + "' provides"));
      } catch (const std::invalid_argument& e) {
        if (std::string(e.what()).rfind(file, 0) == 0) throw;
        fail_at(p, file, e.what());
      }
    }
    for (const auto& b : a["bundles"]) {
      allow_keys(b, file, "bundle", {"name", "priority", "resources", "requested", "deadline"});
      const std::string bname = text(b["name"], file, "bundle name");
      const std::string who = "applet '" + name + "' bundle '" + bname + "'";
      std::vector<std::pair<ServiceId, Access>> resources;
      if (!b["resources"] || !b["resources"].IsSequence()) {
        fail_at(b, file, who + ": 'resources' must be a list");
      }
      for (const auto& r : b["resources"]) {
        allow_keys(r, file, "resource", {"service", "access"});
        const Access access = r["access"] ? access_of(r["access"], file) : Access::kExclusive;
        resources.emplace_back(service_at(model, r["service"], file, who), access);
      }
      const int prio = b["priority"] ? parse_priority(b["priority"], file) : kPriorityNormal;
      const bool requested = flag(b["requested"], file, "requested");
      try {
        const BundleId bid = model.add_bundle(id, bname, resources, prio);
        if (const auto d = b["deadline"]) set_request_deadline(model, c.options, bid, d, file, who);
        if (requested) {
          c.requested_at_start.push_back(bid);
          requested_at.push_back(b);
        }
      } catch (const std::invalid_argument& e) {
        fail_at(b, file, e.what());
      }
    }
  }
  return added;
}

// Requests at start are checked now, with their line, not when a run makes them (e.g. two
// bundles of one applet that both want an exclusive-only service).
void check_requests(const Model& model, const SchedulerOptions& options,
                    const std::vector<BundleId>& requested,
                    const std::vector<YAML::Node>& requested_at, const std::string& file) {
  Scheduler probe(model, options);
  for (std::size_t i = 0; i < requested.size(); ++i) {
    try {
      probe.request(requested[i]);
    } catch (const std::invalid_argument& e) {
      fail_at(requested_at[i], file, e.what());
    }
  }
}

}  // namespace

std::string where(const YAML::Node& node, const std::string& file) {
  if (!node || node.Mark().line < 0) return file;
  return file + ":" + std::to_string(node.Mark().line + 1);
}

std::string read_text_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot read the file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

YAML::Node parse_yaml(const std::string& content, const std::string& file) {
  try {
    return YAML::Load(content);
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(file + ":" + std::to_string(e.mark.line + 1) + ":" +
                                std::to_string(e.mark.column + 1) + ": malformed YAML: " + e.msg);
  }
}

int parse_priority(const YAML::Node& node, const std::string& file) {
  const std::string v = text(node, file, "priority");
  if (v == "low") return kPriorityLow;
  if (v == "normal") return kPriorityNormal;
  if (v == "high") return kPriorityHigh;
  if (v == "system") return kPrioritySystem;
  long long p = 0;
  try {
    p = node.as<long long>();
  } catch (const YAML::Exception&) {
    fail_at(node, file,
            "priority '" + v + "' must be low, normal, high, system or a whole number >= 0");
  }
  if (p < 0 || p > 1000000) fail_at(node, file, "priority " + v + " must lie in 0..1000000");
  return static_cast<int>(p);
}

SystemConfig load_system(const YAML::Node& root, const std::string& file) {
  SystemConfig c;
  if (!root || !root.IsMap()) fail_at(root, file, "the document must be a mapping");
  if (const auto s = root["scheduler"]) {
    allow_keys(
        s, file, "scheduler",
        {"context_switch_ms", "revoke_wait_ms", "negotiation_round_ms", "negotiation_rounds"});
    auto ms_of = [&](const char* key, milliseconds& out) {
      if (!s[key]) return;
      const long long v = number(s[key], file, key);
      if (v < 0) fail_at(s[key], file, std::string(key) + " must not be negative");
      out = milliseconds{v};
    };
    ms_of("context_switch_ms", c.options.context_switch);
    ms_of("revoke_wait_ms", c.options.revoke_wait);
    ms_of("negotiation_round_ms", c.options.negotiation_round_max);
    if (s["negotiation_rounds"]) {
      const long long v = number(s["negotiation_rounds"], file, "negotiation_rounds");
      if (v < 0) fail_at(s["negotiation_rounds"], file, "negotiation_rounds must not be negative");
      c.options.negotiation_rounds_max = static_cast<int>(v);
    }
  }
  const YAML::Node services = root["services"];
  if (!services || !services.IsSequence()) {
    fail_at(services ? services : root, file, "'services' must be a list of services");
  }
  read_services(c.model, services, file, c);
  std::vector<YAML::Node> requested_at;  // per requested_at_start entry, for messages
  read_applets(c.model, root["applets"], file, c, requested_at);
  check_requests(c.model, c.options, c.requested_at_start, requested_at, file);
  return c;
}

LoadedAddition load_addition(const Model& current, const YAML::Node& root,
                             const std::string& file) {
  if (!root || !root.IsMap()) fail_at(root, file, "the document must be a mapping");
  allow_keys(root, file, "an addition", {"services", "applets"});
  const YAML::Node services = root["services"];
  if (services && !services.IsSequence()) {
    fail_at(services, file, "'services' must be a list of services");
  }
  if (!services && !root["applets"]) {
    fail_at(root, file, "an addition names services: or applets: (or both)");
  }
  // Read into a copy of the running model, so that every message has its line; then what the
  // copy gained is the addition, by names.
  SystemConfig c;
  Model probe = current;
  const auto service_ids =
      services ? read_services(probe, services, file, c) : std::vector<ServiceId>{};
  std::vector<YAML::Node> requested_at;
  const auto applet_ids = read_applets(probe, root["applets"], file, c, requested_at);
  check_requests(probe, {}, c.requested_at_start, requested_at, file);
  LoadedAddition out;
  for (const ServiceId id : service_ids) {
    const Service& svc = probe.service(id);
    NewService n{svc.name, svc.exclusive_only, {}};
    for (const Dependency& d : svc.dependencies) {
      n.needs.emplace_back(probe.service(d.service).name, d.access);
    }
    out.addition.services.push_back(std::move(n));
  }
  for (const AppletId id : applet_ids) {
    const Applet& a = probe.applet(id);
    NewApplet n{a.name, a.fail_stop, {}, {}};
    for (const ServiceId p : a.provides) n.provides.push_back(probe.service(p).name);
    for (const BundleId b : a.bundles) {
      NewBundle nb{
          probe.bundle(b).name, probe.bundle(b).priority, {}, probe.bundle(b).request_deadline};
      for (const ResourceId r : probe.bundle(b).resources) {
        nb.resources.emplace_back(probe.service(probe.resource(r).service).name,
                                  probe.resource(r).access);
      }
      n.bundles.push_back(std::move(nb));
    }
    out.addition.applets.push_back(std::move(n));
  }
  for (const BundleId b : c.requested_at_start) {
    out.requested_at_start.emplace_back(probe.applet(probe.bundle(b).applet).name,
                                        probe.bundle(b).name);
  }
  out.applet_params = std::move(c.applet_params);
  out.service_params = std::move(c.service_params);
  return out;
}

}  // namespace oscar::applets
