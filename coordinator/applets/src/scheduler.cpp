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
  revoking_.assign(n, std::nullopt);
  closure_cache_.assign(model_.services().size(), std::nullopt);
  if (options_.revoke_wait.count() < 0 || options_.negotiation_round_max.count() < 0 ||
      options_.negotiation_rounds_max < 0 || options_.context_switch.count() < 0) {
    fail("scheduler options: times and round counts must not be negative");
  }
  replan();
}

void Scheduler::advance_to(milliseconds t) {
  if (t < now_) fail("time " + ms(t) + " lies before now (" + ms(now_) + "); time only advances");
  now_ = t;
  bool changed = false;
  for (BundleId b = 0; b < revoking_.size(); ++b) {
    if (revoking_[b] && revoking_[b]->until <= now_) {
      // Seed §4.6.1: the wait limit passed, the resource is revoked by force.
      revoking_[b].reset();
      active_[b] = 0;
      changed = true;
      notifications_.push_back(Notification{
          Notification::Kind::kRevokedByForce, model_.bundle(b).applet, b, {}, {}, now_});
    }
  }
  if (changed) update_handover();
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

void Scheduler::request(BundleId bundle) {
  if (state_.at(bundle).requested) return;
  check_bundle(bundle);
  state_[bundle].requested = true;
  replan();
}

void Scheduler::release(BundleId bundle) {
  BundleState& s = state_.at(bundle);
  if (!s.requested && !active_[bundle]) return;
  s.requested = false;
  s.boosted = false;
  active_[bundle] = 0;
  revoking_[bundle].reset();
  replan();
}

void Scheduler::yield(BundleId bundle) {
  if (!revoking_.at(bundle)) return;  // nothing to hand back: the bundle stays where it is
  revoking_[bundle].reset();
  active_[bundle] = 0;
  update_handover();
}

void Scheduler::set_priority(BundleId bundle, int priority) {
  if (priority < 0) {
    fail("applet '" + model_.applet(model_.bundle(bundle).applet).name + "' bundle '" +
         model_.bundle(bundle).name + "': priority " + std::to_string(priority) +
         " must not be negative");
  }
  state_.at(bundle).priority = priority;
  replan();
}

void Scheduler::set_deadline(BundleId bundle, std::optional<Deadline> deadline) {
  if (deadline) {
    const Deadline& d = *deadline;
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
  for (BundleId b : model_.applet(applet).bundles) {
    state_[b].requested = false;
    state_[b].boosted = false;
    active_[b] = 0;
    revoking_[b].reset();
  }
  replan();
}

Notification Scheduler::negotiate(BundleId bundle, const Negotiation& answer) {
  auto& rev = revoking_.at(bundle);
  const Bundle& b = model_.bundle(bundle);
  if (!rev) {
    fail("applet '" + model_.applet(b.applet).name + "' negotiates over bundle '" + b.name +
         "' which is not being revoked");
  }
  if (answer.min_needed.count() < 0 || answer.max_needed < answer.min_needed) {
    fail("applet '" + model_.applet(b.applet).name + "' bundle '" + b.name +
         "': a negotiation needs 0 <= min_needed <= max_needed");
  }
  ++rev->rounds;
  // Latest time the new holders can wait: the earliest relative deadline among the granted
  // bundles that need what this one holds (their deadlines bound the extra time, seed §4.6.1).
  milliseconds latest = milliseconds::max();
  for (BundleId g = 0; g < state_.size(); ++g) {
    if (g == bundle || !plan_.bundle_granted[g] || active_[g] || !state_[g].deadline) continue;
    if (conflicts(g, bundle)) latest = std::min(latest, state_[g].deadline->relative());
  }
  auto fits = [&](milliseconds t) {
    return t <= options_.negotiation_round_max &&
           (latest == milliseconds::max() || now_ + t + options_.context_switch <= latest);
  };
  Notification n{Notification::Kind::kNegotiationRejected, b.applet, bundle, {}, {}, rev->until};
  if (answer.accept && rev->rounds <= options_.negotiation_rounds_max) {
    std::optional<milliseconds> granted;
    if (fits(answer.max_needed)) {
      granted = answer.max_needed;
    } else if (fits(answer.min_needed)) {
      granted = answer.min_needed;
    }
    if (granted) {
      rev->until = std::max(rev->until, now_ + *granted);
      n.kind = Notification::Kind::kNegotiationAccepted;
      n.until = rev->until;
    }
  }
  notifications_.push_back(n);
  return n;
}

std::optional<milliseconds> Scheduler::revoke_deadline(BundleId bundle) const {
  if (!revoking_.at(bundle)) return std::nullopt;
  return revoking_[bundle]->until;
}

void Scheduler::replan() {
  Plan next = calculate_assignments(model_, state_, plan_.order, plan_.bundle_granted,
                                    options_.context_switch);
  ++plans_;
  for (const auto& pair : next.deadline_overlaps) {
    if (std::binary_search(plan_.deadline_overlaps.begin(), plan_.deadline_overlaps.end(), pair)) {
      continue;
    }
    for (auto [a, b] : {pair, std::pair{pair.second, pair.first}}) {
      notifications_.push_back(Notification{
          Notification::Kind::kDeadlineOverlap, model_.bundle(a).applet, a, {}, b, now_});
    }
  }
  plan_ = std::move(next);
  update_handover();
}

const std::vector<ServiceId>& Scheduler::closure(ServiceId service) const {
  auto& slot = closure_cache_.at(service);
  if (!slot) {
    std::set<ServiceId> seen{service};
    std::vector<ServiceId> to_visit{service};
    while (!to_visit.empty()) {
      const ServiceId s = to_visit.back();
      to_visit.pop_back();
      for (const Use& u : model_.needs(s)) {
        if (seen.insert(u.service).second) to_visit.push_back(u.service);
      }
    }
    slot.emplace(seen.begin(), seen.end());
  }
  return *slot;
}

bool Scheduler::conflicts(BundleId a, BundleId b) const {
  for (ResourceId ra : model_.bundle(a).resources) {
    for (ResourceId rb : model_.bundle(b).resources) {
      const auto& ca = closure(model_.resource(ra).service);
      const auto& cb = closure(model_.resource(rb).service);
      auto i = ca.begin();
      auto j = cb.begin();
      while (i != ca.end() && j != cb.end()) {
        if (*i == *j) return true;
        if (*i < *j) {
          ++i;
        } else {
          ++j;
        }
      }
    }
  }
  return false;
}

// The per-service reassigners (seed §4.4.1, Abb. 4.13): inform holders the plan no longer
// grants, cancel revocations the plan undid, and hand a granted bundle over once nothing it
// conflicts with is still being given back.
void Scheduler::update_handover() {
  const std::size_t n = state_.size();
  for (BundleId b = 0; b < n; ++b) {
    if (!active_[b]) continue;
    if (plan_.bundle_granted[b]) {
      if (revoking_[b]) {
        revoking_[b].reset();
        notifications_.push_back(
            Notification{Notification::Kind::kGranted, model_.bundle(b).applet, b, {}, {}, now_});
      }
      continue;
    }
    if (revoking_[b]) continue;
    revoking_[b] = Revocation{now_ + options_.revoke_wait, 0};
    std::set<AppletId> to;
    for (BundleId g = 0; g < n; ++g) {
      if (g != b && plan_.bundle_granted[g] && !active_[g] &&
          model_.bundle(g).applet != model_.bundle(b).applet && conflicts(g, b)) {
        to.insert(model_.bundle(g).applet);
      }
    }
    notifications_.push_back(Notification{Notification::Kind::kRevokeRequested,
                                          model_.bundle(b).applet,
                                          b,
                                          std::vector<AppletId>(to.begin(), to.end()),
                                          {},
                                          revoking_[b]->until});
  }
  std::vector<BundleId> giving_back;
  for (BundleId b = 0; b < n; ++b) {
    if (revoking_[b]) giving_back.push_back(b);
  }
  for (BundleId b = 0; b < n; ++b) {
    if (active_[b] || !plan_.bundle_granted[b]) continue;
    // Bundles granted only through inheritance (a service applet's resources that a user of its
    // service needs) are handed over too: the service applet must be able to use them.
    bool free = true;
    for (BundleId x : giving_back) free = free && !conflicts(b, x);
    if (!free) continue;
    active_[b] = 1;
    notifications_.push_back(
        Notification{Notification::Kind::kGranted, model_.bundle(b).applet, b, {}, {}, now_});
  }
}

std::string Scheduler::holder(ServiceId service) const {
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
    if (!state_[b].requested) continue;
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
