#include "oscar/applets/scheduler.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace oscar::applets {
namespace {

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

std::string ms(milliseconds t) { return std::to_string(t.count()) + " ms"; }

}  // namespace

Scheduler::Scheduler(Model model, SchedulerOptions options)
    : model_(std::move(model)), options_(options) {
  const std::size_t n = model_.bundles().size();
  state_.resize(n);
  for (BundleId b = 0; b < n; ++b) {
    if (model_.bundle(b).priority < 0) {
      fail("applet '" + model_.applet(model_.bundle(b).applet).name + "' bundle '" +
           model_.bundle(b).name + "': priority must not be negative");
    }
    state_[b].priority = model_.bundle(b).priority;
  }
  active_.assign(n, 0);
  revoking_.assign(n, 0);
  reassigners_.resize(model_.services().size());
  crashed_.assign(model_.applets().size(), 0);
  provider_gone_.assign(model_.services().size(), 0);
  plan_context_.unavailable.assign(model_.services().size(), 0);
  footprint_cache_.assign(n, std::nullopt);
  services_cache_.assign(n, std::nullopt);
  own_cache_.assign(n, std::nullopt);
  if (options_.revoke_wait.count() < 0 || options_.negotiation_round_max.count() < 0 ||
      options_.negotiation_rounds_max < 0 || options_.context_switch.count() < 0) {
    fail("scheduler options: times and round counts must not be negative");
  }
  replan();
}

void Scheduler::check_bundle(BundleId bundle) const {
  const Bundle& mine = model_.bundle(bundle);
  for (BundleId other : model_.applet(mine.applet).bundles) {
    if (other == bundle || !state_[other].requested) continue;
    for (ResourceId r : mine.resources) {
      for (ResourceId o : model_.bundle(other).resources) {
        const Resource& a = model_.resource(r);
        const Resource& b = model_.resource(o);
        if (a.service == b.service &&
            (a.access == Access::kExclusive || b.access == Access::kExclusive)) {
          fail("applet '" + model_.applet(mine.applet).name + "' requests bundle '" + mine.name +
               "' with service '" + model_.service(a.service).name +
               "' which its requested bundle '" + model_.bundle(other).name +
               "' already uses; an applet cannot use one service from two bundles unless both "
               "are shared (release '" +
               model_.bundle(other).name + "' first)");
        }
      }
    }
  }
}

void Scheduler::check_live(BundleId bundle, const char* what) const {
  const Bundle& b = model_.bundle(bundle);
  if (!b.removed) return;
  fail("applet '" + model_.applet(b.applet).name + "' " + what + " bundle '" + b.name +
       "' but the applet was removed");
}

void Scheduler::request(BundleId bundle) {
  check_live(bundle, "requests");
  if (state_.at(bundle).requested) return;
  const AppletId applet = model_.bundle(bundle).applet;
  if (crashed_[applet]) {
    fail("applet '" + model_.applet(applet).name + "' requests bundle '" +
         model_.bundle(bundle).name + "' but it crashed; a crashed applet requests nothing");
  }
  check_bundle(bundle);
  if (const auto& d = model_.bundle(bundle).request_deadline) {
    const Deadline from_now{now_ + d->t_early, d->t_duration, now_ + d->t_finish};
    check_deadline(bundle, from_now);
    state_[bundle].deadline = from_now;
  }
  state_[bundle].requested = true;
  replan();
}

void Scheduler::release(BundleId bundle) {
  BundleState& s = state_.at(bundle);
  if (!s.requested && !active_[bundle]) return;
  s.requested = false;
  s.boosted = false;
  active_[bundle] = 0;
  stop_giving(bundle);
  replan();
}

void Scheduler::yield(BundleId bundle) {
  if (!revoking_.at(bundle)) return;  // nothing to hand back: the bundle stays where it is
  stop_giving(bundle);
  active_[bundle] = 0;
  update_handover();
}

void Scheduler::set_priority(BundleId bundle, int priority) {
  check_live(bundle, "sets the priority of");
  if (priority < 0) {
    fail("applet '" + model_.applet(model_.bundle(bundle).applet).name + "' bundle '" +
         model_.bundle(bundle).name + "': priority " + std::to_string(priority) +
         " must not be negative");
  }
  state_.at(bundle).priority = priority;
  replan();
}

void Scheduler::check_deadline(BundleId bundle, const Deadline& d) const {
  const milliseconds c = options_.context_switch;
  const std::string who = "applet '" + model_.applet(model_.bundle(bundle).applet).name +
                          "' bundle '" + model_.bundle(bundle).name + "': deadline ";
  if (d.t_duration.count() < 0) fail(who + "t_duration " + ms(d.t_duration) + " is negative");
  if (d.t_early + d.t_duration + c > d.t_finish) {
    fail(who + "needs t_early + t_duration + c <= t_finish (eq. 4.9), but " + ms(d.t_early) +
         " + " + ms(d.t_duration) + " + " + ms(c) + " > " + ms(d.t_finish));
  }
  if (now_ + d.t_duration + c > d.t_finish) {
    fail(who + "needs now + t_duration + c <= t_finish (eq. 4.10), but " + ms(now_) + " + " +
         ms(d.t_duration) + " + " + ms(c) + " > " + ms(d.t_finish));
  }
}

void Scheduler::set_deadline(BundleId bundle, std::optional<Deadline> deadline) {
  check_live(bundle, "sets a deadline on");
  if (deadline) check_deadline(bundle, *deadline);
  state_.at(bundle).deadline = deadline;
  replan();
}

void Scheduler::trigger(BundleId bundle) {
  if (!state_.at(bundle).requested) {
    fail("applet '" + model_.applet(model_.bundle(bundle).applet).name + "' triggers bundle '" +
         model_.bundle(bundle).name + "' which it has not requested; request it first");
  }
  // Seed §4.5.2: raise for one plan; the stable sort keeps the new order after restoring.
  state_[bundle].boosted = true;
  replan();
  state_[bundle].boosted = false;
  replan();
}

void Scheduler::crash(AppletId applet) {
  crashed_.at(applet) = 1;
  for (ServiceId s : model_.applet(applet).provides) provider_gone_[s] = 1;
  for (BundleId b : model_.applet(applet).bundles) {
    state_[b].requested = false;
    state_[b].boosted = false;
    active_[b] = 0;
    stop_giving(b);
  }
  // Its services are gone (seed §4.6.1, cascading effects).
  for (ServiceId s : model_.applet(applet).provides) plan_context_.unavailable[s] = 1;
  revoke_unavailable();
}

void Scheduler::set_available(ServiceId service, bool available) {
  auto& gone = plan_context_.unavailable.at(service);
  if (available && provider_gone_[service]) return;  // until an applet provides it again
  if ((gone == 0) == available) return;
  gone = available ? 0 : 1;
  if (available) {
    replan();
  } else {
    revoke_unavailable();
  }
}

void Scheduler::revoke_unavailable() {
  // Whoever uses an unavailable service, directly or down the hierarchy, loses it now — there
  // is nothing left to hand back — and is told so.
  const std::vector<char>& gone = plan_context_.unavailable;
  for (BundleId b = 0; b < state_.size(); ++b) {
    if (!active_[b]) continue;
    const auto& services = services_of(b);
    const auto lost =
        std::find_if(services.begin(), services.end(), [&](ServiceId s) { return gone[s] != 0; });
    if (lost == services.end()) continue;
    stop_giving(b);
    active_[b] = 0;
    notifications_.push_back(notice(Notification::Kind::kRevokedByForce, b, *lost));
  }
  replan();
}

void Scheduler::replan() {
  plan_context_.now = now_;
  plan_context_.context_switch = options_.context_switch;
  const auto started = std::chrono::steady_clock::now();
  Plan next =
      calculate_assignments(model_, state_, plan_.order, plan_.bundle_granted, plan_context_);
  last_plan_time_ = std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::steady_clock::now() - started);
  ++plans_;
  for (const auto& pair : next.deadline_overlaps) {
    if (std::binary_search(plan_.deadline_overlaps.begin(), plan_.deadline_overlaps.end(), pair)) {
      continue;
    }
    for (auto [a, b] : {pair, std::pair{pair.second, pair.first}}) {
      Notification n = notice(Notification::Kind::kDeadlineOverlap, a);
      n.other = b;
      notifications_.push_back(std::move(n));
    }
  }
  plan_ = std::move(next);
  update_handover();
}

std::string Scheduler::holder(ServiceId service) const {
  if (!available(service)) return "unavailable";
  const auto& uses = plan_.uses.at(service);
  std::set<std::string> names;
  for (const GrantedUse& g : uses) {
    if (g.use.by == Use::By::kResource) {
      names.insert(model_.applet(model_.resource(g.use.holder).applet).name);
    }
  }
  if (!names.empty()) {
    std::string out;
    for (const auto& name : names) out += (out.empty() ? "" : ",") + name;
    return out;
  }
  if (!uses.empty()) return "blocked";  // held up by a service that depends on it
  for (BundleId b = 0; b < state_.size(); ++b) {
    // A request waiting for its t_early asks for nothing yet.
    if (!state_[b].requested || waits_for_t_early(state_[b], plan_.time)) continue;
    for (ResourceId r : model_.bundle(b).resources) {
      if (model_.resource(r).service == service) return "blocked";
    }
  }
  const Access probe =
      model_.service(service).exclusive_only ? Access::kExclusive : Access::kShared;
  return can_grant(model_, plan_, service, probe) ? "undef" : "blocked";
}

std::string Scheduler::active_holder(ServiceId service) const {
  std::set<std::string> names;
  for (BundleId b = 0; b < active_.size(); ++b) {
    if (!active_[b]) continue;
    for (ResourceId r : model_.bundle(b).resources) {
      if (model_.resource(r).service == service) {
        names.insert(model_.applet(model_.bundle(b).applet).name);
      }
    }
  }
  std::string out;
  for (const auto& name : names) out += (out.empty() ? "" : ",") + name;
  return out.empty() ? "none" : out;
}

std::vector<Notification> Scheduler::take_notifications() {
  std::vector<Notification> out;
  out.swap(notifications_);
  return out;
}

}  // namespace oscar::applets
