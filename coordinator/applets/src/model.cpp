#include "oscar/applets/model.hpp"

#include <algorithm>
#include <functional>
#include <stdexcept>

namespace oscar::applets {
namespace {

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

}  // namespace

std::string_view to_string(Access access) {
  return access == Access::kExclusive ? "exclusive" : "shared";
}

ServiceId Model::add_service(std::string name, bool exclusive_only) {
  if (name.empty()) fail("service: the name must not be empty");
  if (service_ids_.count(name)) fail("service '" + name + "' is declared twice; names are unique");
  const auto id = static_cast<ServiceId>(services_.size());
  service_ids_.emplace(name, id);
  services_.push_back(Service{std::move(name), exclusive_only, std::nullopt, {}});
  invalidate();
  return id;
}

void Model::add_dependency(ServiceId service, ServiceId dependency, Access access) {
  Service& s = services_.at(service);
  const std::string& dep_name = services_.at(dependency).name;
  if (s.removed) fail("service '" + s.name + "' was removed; it needs nothing any more");
  if (services_[dependency].removed) {
    fail("service '" + s.name + "' cannot need service '" + dep_name + "': it was removed");
  }
  if (service == dependency) fail("service '" + s.name + "' cannot depend on itself");
  for (const Dependency& d : s.dependencies) {
    if (d.service == dependency) {
      fail("service '" + s.name + "' lists dependency '" + dep_name + "' twice");
    }
  }
  if (access == Access::kShared && services_[dependency].exclusive_only) {
    fail("service '" + s.name + "' depends on exclusive-only service '" + dep_name +
         "' with shared access; use exclusive");
  }
  s.dependencies.push_back(Dependency{dependency, access});
  invalidate();
}

AppletId Model::add_applet(std::string name, bool fail_stop) {
  if (name.empty()) fail("applet: the name must not be empty");
  if (applet_ids_.count(name)) fail("applet '" + name + "' is declared twice; names are unique");
  const auto id = static_cast<AppletId>(applets_.size());
  applet_ids_.emplace(name, id);
  Applet a;
  a.name = std::move(name);
  a.fail_stop = fail_stop;
  applets_.push_back(std::move(a));
  invalidate();
  return id;
}

void Model::provide(AppletId applet, ServiceId service) {
  Service& s = services_.at(service);
  Applet& a = applets_.at(applet);
  if (a.removed) fail("applet '" + a.name + "' was removed; it provides nothing any more");
  if (s.removed) {
    fail("applet '" + a.name + "' cannot provide service '" + s.name + "': it was removed");
  }
  if (s.provider && *s.provider != applet) {
    fail("service '" + s.name + "' is already provided by applet '" + applets_[*s.provider].name +
         "'; applet '" + a.name + "' cannot provide it too");
  }
  if (!s.provider) a.provides.push_back(service);
  s.provider = applet;
  invalidate();
}

void Model::set_request_deadline(BundleId bundle, Deadline d) {
  Bundle& b = bundles_.at(bundle);
  const std::string who =
      "applet '" + applets_.at(b.applet).name + "' bundle '" + b.name + "': deadline ";
  if (d.t_early.count() < 0 || d.t_duration.count() < 0) {
    fail(who + "times are counted from the request and cannot be negative");
  }
  if (d.t_early + d.t_duration > d.t_finish) {
    fail(who + "needs early + duration <= finish (eq. 4.9), but " +
         std::to_string(d.t_early.count()) + " ms + " + std::to_string(d.t_duration.count()) +
         " ms > " + std::to_string(d.t_finish.count()) + " ms");
  }
  b.request_deadline = d;
}

BundleId Model::add_bundle(AppletId applet, std::string name,
                           const std::vector<std::pair<ServiceId, Access>>& resources,
                           int priority) {
  Applet& a = applets_.at(applet);
  const std::string where = "applet '" + a.name + "' bundle '" + name + "'";
  if (a.removed) fail("applet '" + a.name + "' was removed; it takes no bundles any more");
  if (name.empty()) fail("applet '" + a.name + "': a bundle needs a name");
  for (BundleId b : a.bundles) {
    if (bundles_[b].name == name) fail(where + " is declared twice; bundle names are unique");
  }
  if (resources.empty()) fail(where + " has no resources; a bundle needs at least one");
  for (std::size_t i = 0; i < resources.size(); ++i) {
    const Service& s = services_.at(resources[i].first);
    if (s.removed) fail(where + " uses service '" + s.name + "', which was removed");
    for (std::size_t j = 0; j < i; ++j) {
      if (resources[j].first == resources[i].first) {
        fail(where + " lists service '" + s.name + "' twice");
      }
    }
    if (s.exclusive_only && resources[i].second == Access::kShared) {
      fail(where + " asks for shared access to exclusive-only service '" + s.name + "'");
    }
  }
  const auto id = static_cast<BundleId>(bundles_.size());
  Bundle b{applet, std::move(name), {}, priority, std::nullopt};
  for (const auto& [service, access] : resources) {
    const auto rid = static_cast<ResourceId>(resources_.size());
    resources_.push_back(Resource{applet, service, access, id});
    b.resources.push_back(rid);
    a.resources.push_back(rid);
  }
  bundles_.push_back(std::move(b));
  a.bundles.push_back(id);
  invalidate();
  return id;
}

AddedIds Model::add(const ModelAddition& addition) {
  // All or nothing: the calls validate one by one, so they run on a copy that replaces this
  // model only once all of them succeeded.
  Model next = *this;
  AddedIds ids;
  for (const NewService& s : addition.services) {
    ids.services.push_back(next.add_service(s.name, s.exclusive_only));
  }
  for (std::size_t i = 0; i < addition.services.size(); ++i) {
    for (const auto& [need, access] : addition.services[i].needs) {
      next.add_dependency(ids.services[i], next.service_id(need), access);
    }
  }
  for (const NewApplet& a : addition.applets) {
    const AppletId id = next.add_applet(a.name, a.fail_stop);
    ids.applets.push_back(id);
    for (const std::string& p : a.provides) next.provide(id, next.service_id(p));
    for (const NewBundle& b : a.bundles) {
      std::vector<std::pair<ServiceId, Access>> resources;
      for (const auto& [service, access] : b.resources) {
        resources.emplace_back(next.service_id(service), access);
      }
      const BundleId bundle = next.add_bundle(id, b.name, resources, b.priority);
      if (b.request_deadline) next.set_request_deadline(bundle, *b.request_deadline);
    }
  }
  *this = std::move(next);
  return ids;
}

void Model::remove_applet(AppletId applet) {
  Applet& a = applets_.at(applet);
  if (a.removed) fail("applet '" + a.name + "' was removed already");
  a.removed = true;
  applet_ids_.erase(a.name);
  for (ServiceId s : a.provides) services_[s].provider.reset();
  a.provides.clear();
  for (BundleId b : a.bundles) bundles_[b].removed = true;
  invalidate();
}

void Model::remove_service(ServiceId service) {
  Service& s = services_.at(service);
  if (s.removed) fail("service '" + s.name + "' was removed already");
  std::vector<std::string> users, needers;
  for (const Applet& a : applets_) {
    if (a.removed) continue;
    const bool uses = std::any_of(a.resources.begin(), a.resources.end(),
                                  [&](ResourceId r) { return resources_[r].service == service; });
    if (uses) users.push_back("'" + a.name + "'");
  }
  for (const Service& other : services_) {
    if (other.removed) continue;
    const bool needs = std::any_of(other.dependencies.begin(), other.dependencies.end(),
                                   [&](const Dependency& d) { return d.service == service; });
    if (needs) needers.push_back("'" + other.name + "'");
  }
  auto joined = [](const std::vector<std::string>& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
  };
  std::string why;
  if (!users.empty()) why += "the bundles of applet(s) " + joined(users) + " use it";
  if (!needers.empty()) {
    why += (why.empty() ? "" : "; ") + std::string("service(s) ") + joined(needers) + " need it";
  }
  if (s.provider) {
    why += (why.empty() ? "" : "; ") + std::string("applet '") + applets_[*s.provider].name +
           "' provides it";
  }
  if (!why.empty()) {
    fail("service '" + s.name + "' cannot be removed while " + why + " (remove them first)");
  }
  s.removed = true;
  s.dependencies.clear();
  service_ids_.erase(s.name);
  invalidate();
}

std::optional<ServiceId> Model::find_service(std::string_view name) const {
  auto it = service_ids_.find(std::string(name));
  if (it == service_ids_.end()) return std::nullopt;
  return it->second;
}

ServiceId Model::service_id(std::string_view name) const {
  if (auto id = find_service(name)) return *id;
  fail("unknown service '" + std::string(name) + "'");
}

AppletId Model::applet_id(std::string_view name) const {
  auto it = applet_ids_.find(std::string(name));
  if (it == applet_ids_.end()) fail("unknown applet '" + std::string(name) + "'");
  return it->second;
}

BundleId Model::bundle_id(AppletId applet, std::string_view name) const {
  for (BundleId b : applets_.at(applet).bundles) {
    if (bundles_[b].name == name) return b;
  }
  fail("applet '" + applets_[applet].name + "' has no bundle '" + std::string(name) + "'");
}

const std::vector<BundleId>& Model::cycle_of(BundleId bundle) const {
  static const std::vector<BundleId> kNone;
  const auto index = cycle_index(bundle);
  return index ? cycles_[*index] : kNone;
}

void Model::analyse() const {
  if (analysed_) return;
  const std::size_t n = services_.size();
  needs_.clear();
  needs_begin_.assign(1, 0);
  for (ServiceId s = 0; s < n; ++s) {
    for (const Dependency& d : services_[s].dependencies) {
      needs_.push_back(Use{d.service, d.access, Use::By::kService, s});
    }
    if (services_[s].provider) {
      for (ResourceId r : applets_[*services_[s].provider].resources) {
        needs_.push_back(Use{resources_[r].service, resources_[r].access, Use::By::kResource, r});
      }
    }
    needs_begin_.push_back(static_cast<std::uint32_t>(needs_.size()));
  }
  bundle_uses_.clear();
  bundle_uses_begin_.assign(1, 0);
  for (const Bundle& b : bundles_) {
    for (ResourceId r : b.resources) {
      bundle_uses_.push_back(
          Use{resources_[r].service, resources_[r].access, Use::By::kResource, r});
    }
    bundle_uses_begin_.push_back(static_cast<std::uint32_t>(bundle_uses_.size()));
  }
  // Strongly connected components of the service graph (Tarjan, iterative enough for the sizes
  // of applet systems; recursion depth is bounded by the number of services).
  std::vector<int> index(n, -1), low(n, 0), comp(n, -1);
  std::vector<char> on_stack(n, 0);
  std::vector<ServiceId> stack;
  int counter = 0, comps = 0;
  std::function<void(ServiceId)> visit = [&](ServiceId v) {
    index[v] = low[v] = counter++;
    stack.push_back(v);
    on_stack[v] = 1;
    for (const Use& u : std::span<const Use>(needs_.data() + needs_begin_[v],
                                             needs_begin_[v + 1] - needs_begin_[v])) {
      const ServiceId w = u.service;
      if (index[w] < 0) {
        visit(w);
        low[v] = std::min(low[v], low[w]);
      } else if (on_stack[w]) {
        low[v] = std::min(low[v], index[w]);
      }
    }
    if (low[v] == index[v]) {
      ServiceId w;
      do {
        w = stack.back();
        stack.pop_back();
        on_stack[w] = 0;
        comp[w] = comps;
      } while (w != v);
      ++comps;
    }
  };
  for (ServiceId s = 0; s < n; ++s) {
    if (index[s] < 0) visit(s);
  }
  std::vector<int> comp_size(comps, 0);
  for (ServiceId s = 0; s < n; ++s) ++comp_size[comp[s]];
  // A bundle lies on a cycle if its applet provides a service of a cyclic component and one of
  // its resources uses a service of the same component (seed Abb. 4.9).
  std::vector<std::vector<BundleId>> members(comps);
  for (BundleId b = 0; b < bundles_.size(); ++b) {
    const Applet& a = applets_[bundles_[b].applet];
    int found = -1;
    for (ServiceId p : a.provides) {
      for (ResourceId r : bundles_[b].resources) {
        const ServiceId s = resources_[r].service;
        if (comp[s] == comp[p] && (comp_size[comp[p]] > 1 || s == p)) found = comp[p];
      }
    }
    if (found >= 0) members[found].push_back(b);
  }
  // Each cycle's members once (a copy per member was quadratic in the size of a cycle).
  cycles_.clear();
  cycle_index_.assign(bundles_.size(), kNoCycle);
  for (auto& m : members) {
    if (m.empty()) continue;
    for (BundleId b : m) cycle_index_[b] = static_cast<std::uint32_t>(cycles_.size());
    cycles_.push_back(std::move(m));
  }
  analysed_ = true;
}

}  // namespace oscar::applets
