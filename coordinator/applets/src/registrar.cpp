// The Scheduler as the registrar of services and applets (seed 000 §4.1.1): it is told of their
// presence and absence while it runs, and plans with what is there. Ids only grow: a removed
// applet's or service's id is never given again, so every per-id table keeps its meaning.

#include <algorithm>
#include <stdexcept>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {
namespace {

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

}  // namespace

void Scheduler::fit_to_model() {
  const std::size_t n = model_.bundles().size();
  const std::size_t services = model_.services().size();
  for (BundleId b = static_cast<BundleId>(state_.size()); b < n; ++b) {
    BundleState st;
    st.priority = model_.bundle(b).priority;
    state_.push_back(st);
  }
  active_.resize(n, 0);
  revoking_.resize(n, 0);
  reassigners_.resize(services);
  crashed_.resize(model_.applets().size(), 0);
  provider_gone_.resize(services, 0);
  plan_context_.unavailable.resize(services, 0);
  // What a service needs may have changed (a new provider, a provider gone). Only bundles that
  // hold nothing can be affected (add() and remove_applet() see to it), and only holders have
  // reassigners that remember their footprint, so forgetting all of it is safe.
  footprint_cache_.assign(n, std::nullopt);
  services_cache_.assign(n, std::nullopt);
  own_cache_.assign(n, std::nullopt);
}

AddedIds Scheduler::add(const ModelAddition& addition) {
  for (const NewApplet& a : addition.applets) {
    for (const NewBundle& b : a.bundles) {
      if (b.priority < 0) {
        fail("applet '" + a.name + "' bundle '" + b.name + "': priority must not be negative");
      }
    }
    // A new provider changes what its service needs: a bundle holding the service now would
    // suddenly need more than it was granted.
    for (const std::string& p : a.provides) {
      const auto service = model_.find_service(p);
      if (!service) continue;
      for (BundleId b = 0; b < active_.size(); ++b) {
        if (!active_[b]) continue;
        const auto& used = services_of(b);
        if (!std::binary_search(used.begin(), used.end(), *service)) continue;
        fail("applet '" + a.name + "' cannot provide service '" + p + "' now: applet '" +
             model_.applet(model_.bundle(b).applet).name + "' holds it (bundle '" +
             model_.bundle(b).name + "'); an added applet provides a service nobody holds");
      }
    }
  }
  const AddedIds ids = model_.add(addition);
  fit_to_model();
  for (const AppletId a : ids.applets) {
    for (const ServiceId s : model_.applet(a).provides) {
      if (!provider_gone_[s]) continue;
      provider_gone_[s] = 0;  // provided again
      plan_context_.unavailable[s] = 0;
    }
  }
  replan();
  return ids;
}

void Scheduler::remove_applet(AppletId applet) {
  const Applet& a = model_.applet(applet);
  if (a.removed) fail("applet '" + a.name + "' was removed already");
  // As when it ends: its bundles are given back at once, and what it provided is gone (the
  // holders of those services lose them, seed §4.6.1) — all with the model it had.
  for (BundleId b : a.bundles) {
    state_[b].requested = false;
    state_[b].boosted = false;
    state_[b].deadline.reset();
    active_[b] = 0;
    stop_giving(b);
  }
  for (ServiceId s : a.provides) {
    provider_gone_[s] = 1;
    plan_context_.unavailable[s] = 1;
  }
  revoke_unavailable();
  std::erase_if(notifications_, [&](const Notification& n) { return n.applet == applet; });
  model_.remove_applet(applet);
  fit_to_model();
  replan();
}

void Scheduler::remove_service(ServiceId service) {
  model_.remove_service(service);  // refused while anything uses it
  reassigners_.at(service) = Reassignment{};
  fit_to_model();
  replan();
}

}  // namespace oscar::applets
