// The per-service reassigners of the Scheduler (seed 000 §4.4.1, Abb. 4.13–4.14; §4.5.3;
// §4.6.1). After every plan, each service whose holders no longer match the plan gets a
// reassigner: it informs the holders (and whom the service goes to), passes their negotiation on
// to the scheduler, waits for them to yield, revokes by force after the wait limit, and grants
// the service to the new holders once nobody clashing with them still holds it. Bundles stay all
// or nothing: a holder gives back a whole bundle, so a bundle being revoked involves the
// reassigners of every service it uses, and a new bundle is handed over once the reassigners of
// all its services let it.

#include <algorithm>
#include <stdexcept>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {

Notification Scheduler::notice(Notification::Kind kind, BundleId bundle,
                               std::optional<ServiceId> service) const {
  Notification n;
  n.kind = kind;
  n.applet = model_.bundle(bundle).applet;
  n.bundle = bundle;
  n.until = now_;
  n.service = service;
  return n;
}

const std::vector<Scheduler::FootUse>& Scheduler::footprint(BundleId bundle) const {
  auto& slot = footprint_cache_.at(bundle);
  if (slot) return *slot;
  std::vector<FootUse> out;
  std::vector<char> expanded(model_.services().size(), 0);
  std::vector<ServiceId> to_expand;
  for (ResourceId r : model_.bundle(bundle).resources) {
    const Resource& res = model_.resource(r);
    out.push_back(FootUse{res.service, Use::By::kResource, r, res.access == Access::kExclusive});
    to_expand.push_back(res.service);
  }
  // A service used at all uses what it needs once (plan.cpp: expand), whoever uses it.
  while (!to_expand.empty()) {
    const ServiceId s = to_expand.back();
    to_expand.pop_back();
    if (expanded[s]) continue;
    expanded[s] = 1;
    for (const Use& u : model_.needs(s)) {
      out.push_back(FootUse{u.service, u.by, u.holder, u.access == Access::kExclusive});
      to_expand.push_back(u.service);
    }
  }
  std::sort(out.begin(), out.end(),
            [](const FootUse& a, const FootUse& b) { return a.service < b.service; });
  slot = std::move(out);
  return *slot;
}

const std::vector<ServiceId>& Scheduler::services_of(BundleId bundle) const {
  auto& slot = services_cache_.at(bundle);
  if (!slot) {
    std::vector<ServiceId> out;
    for (const FootUse& f : footprint(bundle)) {
      if (out.empty() || out.back() != f.service) out.push_back(f.service);
    }
    slot = std::move(out);
  }
  return *slot;
}

bool Scheduler::uses_itself(BundleId bundle, ServiceId service) const {
  auto& slot = own_cache_.at(bundle);
  if (!slot) {
    std::vector<ServiceId> own;
    std::vector<ServiceId> to_visit;
    for (ResourceId r : model_.bundle(bundle).resources) {
      to_visit.push_back(model_.resource(r).service);
    }
    while (!to_visit.empty()) {
      const ServiceId s = to_visit.back();
      to_visit.pop_back();
      if (std::find(own.begin(), own.end(), s) != own.end()) continue;
      own.push_back(s);
      for (const Use& u : model_.needs(s)) {
        if (u.by == Use::By::kService) to_visit.push_back(u.service);
      }
    }
    std::sort(own.begin(), own.end());
    slot = std::move(own);
  }
  return std::binary_search(slot->begin(), slot->end(), service);
}

bool Scheduler::conflicts(BundleId a, BundleId b) const {
  const auto& fa = footprint(a);
  const auto& fb = footprint(b);
  auto i = fa.begin();
  auto j = fb.begin();
  while (i != fa.end() && j != fb.end()) {
    if (i->service < j->service) {
      ++i;
    } else if (j->service < i->service) {
      ++j;
    } else {
      const ServiceId s = i->service;
      auto i_end = i;
      while (i_end != fa.end() && i_end->service == s) ++i_end;
      auto j_end = j;
      while (j_end != fb.end() && j_end->service == s) ++j_end;
      for (auto x = i; x != i_end; ++x) {
        for (auto y = j; y != j_end; ++y) {
          const bool same_user = x->by == y->by && x->user == y->user;
          if (!same_user && (x->exclusive || y->exclusive)) return true;
        }
      }
      i = i_end;
      j = j_end;
    }
  }
  return false;
}

void Scheduler::start_giving(BundleId bundle) {
  revoking_[bundle] = 1;
  for (ServiceId s : services_of(bundle)) {
    reassigners_[s].giving.push_back(Reassignment::Giving{bundle, now_ + options_.revoke_wait, 0});
  }
}

void Scheduler::stop_giving(BundleId bundle) {
  if (!revoking_.at(bundle)) return;
  revoking_[bundle] = 0;
  for (ServiceId s : services_of(bundle)) {
    auto& giving = reassigners_[s].giving;
    std::erase_if(giving, [&](const Reassignment::Giving& g) { return g.bundle == bundle; });
    if (giving.empty()) reassigners_[s].to.clear();
  }
}

std::optional<milliseconds> Scheduler::revoke_deadline(BundleId bundle) const {
  if (!revoking_.at(bundle)) return std::nullopt;
  milliseconds until = milliseconds::max();
  for (ServiceId s : services_of(bundle)) {
    for (const auto& g : reassigners_[s].giving) {
      if (g.bundle == bundle) until = std::min(until, g.until);
    }
  }
  return until;
}

std::optional<milliseconds> Scheduler::next_forced_revocation() const {
  std::optional<milliseconds> next;
  for (const Reassignment& r : reassigners_) {
    for (const auto& g : r.giving) {
      if (!next || g.until < *next) next = g.until;
    }
  }
  return next;
}

std::optional<milliseconds> Scheduler::next_event() const {
  std::optional<milliseconds> next = next_forced_revocation();
  auto consider = [&](milliseconds t) {
    if (!next || t < *next) next = t;
  };
  for (const BundleState& b : state_) {
    if (!b.requested || !b.deadline) continue;
    consider(b.deadline->t_finish);                                       // expiry
    if (waits_for_t_early(b, plan_.time)) consider(b.deadline->t_early);  // planned then
  }
  return next;
}

void Scheduler::advance_to(milliseconds t) {
  if (t < now_) {
    throw std::invalid_argument("time " + std::to_string(t.count()) + " ms lies before now (" +
                                std::to_string(now_.count()) + " ms); time only advances");
  }
  // Everything that falls due on the way happens at its own time, in order (a revocation by
  // force at 3000 ms hands over before a request planned at 5000 ms, and is stamped 3000 ms).
  for (auto next = next_event(); next && *next <= t; next = next_event()) {
    now_ = std::max(now_, *next);
    handle_due();
  }
  now_ = t;
}

void Scheduler::handle_due() {
  // Seed §4.5.1: t_finish is the latest end of the access; after it the request is withdrawn.
  // A bundle still in use is given back through its reassigners (the plan no longer grants it).
  bool replan_now = false;
  for (BundleId b = 0; b < state_.size(); ++b) {
    BundleState& st = state_[b];
    if (!st.requested || !st.deadline) continue;
    if (st.deadline->t_finish <= now_) {
      Notification n = notice(Notification::Kind::kDeadlineExpired, b);
      n.until = st.deadline->t_finish;
      notifications_.push_back(std::move(n));
      st.requested = false;
      st.boosted = false;
      st.deadline.reset();
      replan_now = true;
    } else if (waits_for_t_early(st, plan_.time) && st.deadline->t_early <= now_) {
      replan_now = true;  // its earliest start is reached: the plan considers it now
    }
  }
  if (replan_now) replan();
  // Seed §4.6.1: a reassigner whose wait limit for a holder passed revokes by force; the holder
  // loses its whole bundle (all or nothing), so it leaves the other reassigners too.
  std::vector<std::pair<BundleId, ServiceId>> overdue;
  for (ServiceId s = 0; s < reassigners_.size(); ++s) {
    for (const auto& g : reassigners_[s].giving) {
      if (g.until <= now_) overdue.emplace_back(g.bundle, s);
    }
  }
  for (auto [b, s] : overdue) {
    if (!revoking_[b]) continue;  // already forced by an earlier reassigner
    stop_giving(b);
    active_[b] = 0;
    // Named after the service whose wait limit passed, if the holder heard from its reassigner.
    notifications_.push_back(
        notice(Notification::Kind::kRevokedByForce, b,
               uses_itself(b, s) ? std::optional<ServiceId>{s} : std::nullopt));
  }
  if (!overdue.empty()) update_handover();
}

Notification Scheduler::negotiate_with(ServiceId service, Reassignment::Giving& giving,
                                       const Negotiation& answer) {
  const BundleId bundle = giving.bundle;
  ++giving.rounds;
  // The new holders of this service bound the extra time: none may miss its latest start
  // (t_finish − t_duration, with the context switch), seed §4.6.1.
  milliseconds latest = milliseconds::max();
  for (BundleId g = 0; g < state_.size(); ++g) {
    if (g == bundle || !plan_.bundle_granted[g] || active_[g] || !state_[g].deadline) continue;
    const auto& mine = services_of(g);
    if (std::binary_search(mine.begin(), mine.end(), service) && conflicts(g, bundle)) {
      latest = std::min(latest, state_[g].deadline->relative());
    }
  }
  auto fits = [&](milliseconds t) {
    return t <= options_.negotiation_round_max &&
           (latest == milliseconds::max() || now_ + t + options_.context_switch <= latest);
  };
  Notification n = notice(Notification::Kind::kNegotiationRejected, bundle, service);
  n.until = giving.until;
  if (giving.rounds <= options_.negotiation_rounds_max) {
    // The vote decides what the applet asks for (seed §4.5.3, §4.6.1): agreeing to the
    // revocation, it takes max_needed if that fits, else min_needed (a compromise); objecting to
    // it, it insists on keeping the bundle for max_needed, and the objection is upheld only if
    // that fits. A rejected objection leaves the applet its on_reject round to offer less.
    std::optional<milliseconds> granted;
    if (fits(answer.max_needed)) {
      granted = answer.max_needed;
    } else if (answer.accept && fits(answer.min_needed)) {
      granted = answer.min_needed;
    }
    if (granted) {
      giving.until = std::max(giving.until, now_ + *granted);  // never shortens the wait
      n.kind = Notification::Kind::kNegotiationAccepted;
      n.until = giving.until;
    }
  }
  if (uses_itself(bundle, service)) notifications_.push_back(n);
  return n;
}

Notification Scheduler::negotiate(BundleId bundle, const Negotiation& answer) {
  const Bundle& b = model_.bundle(bundle);
  if (!revoking_.at(bundle)) {
    throw std::invalid_argument("applet '" + model_.applet(b.applet).name +
                                "' negotiates over bundle '" + b.name +
                                "' which is not being revoked");
  }
  if (answer.min_needed.count() < 0 || answer.max_needed < answer.min_needed) {
    throw std::invalid_argument("applet '" + model_.applet(b.applet).name + "' bundle '" + b.name +
                                "': a negotiation needs 0 <= min_needed <= max_needed");
  }
  Notification summary = notice(Notification::Kind::kNegotiationAccepted, bundle);
  summary.until = milliseconds::max();
  for (ServiceId s : services_of(bundle)) {
    for (auto& g : reassigners_[s].giving) {
      if (g.bundle != bundle) continue;
      const Notification n = negotiate_with(s, g, answer);
      if (n.kind != Notification::Kind::kNegotiationAccepted) summary.kind = n.kind;
      summary.until = std::min(summary.until, g.until);
    }
  }
  return summary;
}

void Scheduler::update_handover() {
  const std::size_t n = state_.size();
  // The plan took a revocation back: the holder keeps its bundle and is told to continue.
  std::vector<BundleId> fresh;
  for (BundleId b = 0; b < n; ++b) {
    if (!active_[b]) continue;
    if (plan_.bundle_granted[b]) {
      if (revoking_[b]) {
        stop_giving(b);
        notifications_.push_back(notice(Notification::Kind::kGranted, b));
      }
    } else if (!revoking_[b]) {
      start_giving(b);
      fresh.push_back(b);
    }
  }
  // Whom each running reassigner gives its service to: the planned bundles not yet handed over.
  std::vector<std::vector<AppletId>> to(reassigners_.size());
  for (BundleId g = 0; g < n; ++g) {
    if (active_[g] || !plan_.bundle_granted[g]) continue;
    for (ServiceId s : services_of(g)) {
      if (!reassigners_[s].giving.empty()) to[s].push_back(model_.bundle(g).applet);
    }
  }
  // Inform the holders: a new holder hears from every reassigner of its bundle, an old one again
  // when the service now goes to someone else (seed: applets are told who gets what they lose).
  for (ServiceId s = 0; s < reassigners_.size(); ++s) {
    Reassignment& r = reassigners_[s];
    if (r.giving.empty()) continue;
    std::sort(to[s].begin(), to[s].end());
    to[s].erase(std::unique(to[s].begin(), to[s].end()), to[s].end());
    const bool changed = to[s] != r.to;
    r.to = std::move(to[s]);
    for (const auto& g : r.giving) {
      const bool is_fresh = std::find(fresh.begin(), fresh.end(), g.bundle) != fresh.end();
      if ((!is_fresh && !changed) || !uses_itself(g.bundle, s)) continue;
      Notification told = notice(Notification::Kind::kRevokeRequested, g.bundle, s);
      told.new_holders = r.to;
      told.until = g.until;
      notifications_.push_back(std::move(told));
    }
  }
  // Grant: a planned bundle is handed over when no holder it clashes with still gives back any
  // service of it; bundles granted only through inheritance (a service applet's) too.
  for (BundleId g = 0; g < n; ++g) {
    if (active_[g] || !plan_.bundle_granted[g]) continue;
    bool free = true;
    for (ServiceId s : services_of(g)) {
      for (const auto& x : reassigners_[s].giving) free = free && !conflicts(g, x.bundle);
      if (!free) break;
    }
    if (!free) continue;
    active_[g] = 1;
    notifications_.push_back(notice(Notification::Kind::kGranted, g));
  }
}

}  // namespace oscar::applets
