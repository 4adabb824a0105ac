#include "oscar/applets/plan.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>

namespace oscar::applets {
namespace {

// Who currently uses which service, with an undo journal so that a bundle whose closure fails
// half-way leaves no trace (all or nothing, seed Abb. 4.6 and 4.9).
class Assignment {
 public:
  Assignment(const Model& model, const std::vector<char>& unavailable)
      : model_(model),
        unavailable_(unavailable),
        uses_(model.services().size()),
        exclusive_(model.services().size(), 0),
        expanded_(model.services().size(), 0),
        resource_used_(model.resources().size(), 0) {}

  void add_existing(const GrantedUse& g) {
    if (g.use.by == Use::By::kResource) resource_used_[g.use.holder] = 1;
    uses_[g.use.service].push_back(g);
    if (g.use.access == Access::kExclusive) exclusive_[g.use.service] = 1;
    expanded_[g.use.service] = 1;
  }

  // Tries to grant `uses` rooted at `root` and everything they need; commits or rolls back.
  bool try_grant(const std::vector<Use>& uses, BundleId root) {
    const std::size_t mark = journal_.size();
    bool ok = true;
    for (const Use& u : uses) {
      if (!use(u, root) || !expand(u.service, root)) {
        ok = false;
        break;
      }
    }
    if (!ok) rollback(mark);
    journal_.clear();
    return ok;
  }

  bool probe(const std::vector<Use>& uses) {
    const std::size_t mark = journal_.size();
    bool ok = true;
    for (const Use& u : uses) {
      if (!use(u, 0) || !expand(u.service, 0)) {
        ok = false;
        break;
      }
    }
    rollback(mark);
    return ok;
  }

  std::vector<std::vector<GrantedUse>> take_uses() { return std::move(uses_); }

 private:
  struct Entry {
    enum Kind : std::uint8_t { kUse, kExpanded } kind;
    ServiceId service;
  };

  // Abb. 4.21 steps 1–2: a service given exclusively admits nobody else; an exclusive use
  // admits nobody before it. A resource already in use is no new use (a service applet's
  // resource needed by two of its services); a service's own uses are added once, when it is
  // expanded, so they need no such check.
  bool use(const Use& u, BundleId root) {
    const bool by_resource = u.by == Use::By::kResource;
    if (by_resource && resource_used_[u.holder]) return true;
    if (u.service < unavailable_.size() && unavailable_[u.service]) return false;
    auto& list = uses_[u.service];
    if (exclusive_[u.service]) return false;
    if (u.access == Access::kExclusive && !list.empty()) return false;
    if (by_resource) resource_used_[u.holder] = 1;
    list.push_back(GrantedUse{u, root});
    if (u.access == Access::kExclusive) exclusive_[u.service] = 1;
    journal_.push_back(Entry{Entry::kUse, u.service});
    return true;
  }

  // Abb. 4.21 steps 3–4 and Abb. 4.19 lines 19–24: what a used service needs is used too, by
  // the service itself (configured dependencies) or by its service applet's resources.
  // Services already expanded need nothing new; this also ends the walk around a cycle.
  bool expand(ServiceId s, BundleId root) {
    if (expanded_[s]) return true;
    expanded_[s] = 1;
    journal_.push_back(Entry{Entry::kExpanded, s});
    for (const Use& u : model_.needs(s)) {
      if (!use(u, root) || !expand(u.service, root)) return false;
    }
    return true;
  }

  void rollback(std::size_t mark) {
    while (journal_.size() > mark) {
      const Entry e = journal_.back();
      journal_.pop_back();
      if (e.kind == Entry::kExpanded) {
        expanded_[e.service] = 0;
        continue;
      }
      auto& list = uses_[e.service];
      if (list.back().use.by == Use::By::kResource) resource_used_[list.back().use.holder] = 0;
      list.pop_back();
      // An exclusive use is always a sole use: after removing any use, none is left exclusive.
      exclusive_[e.service] = 0;
    }
  }

  const Model& model_;
  const std::vector<char>& unavailable_;
  std::vector<std::vector<GrantedUse>> uses_;
  std::vector<char> exclusive_;
  std::vector<char> expanded_;
  std::vector<char> resource_used_;
  std::vector<Entry> journal_;
};

std::vector<Use> bundle_uses(const Model& model, BundleId b) {
  std::vector<Use> uses;
  for (ResourceId r : model.bundle(b).resources) {
    const Resource& res = model.resource(r);
    uses.push_back(Use{res.service, res.access, Use::By::kResource, r});
  }
  return uses;
}

}  // namespace

bool waits_for_t_early(const BundleState& state, std::chrono::milliseconds now) {
  return state.requested && state.deadline && state.deadline->t_early > now;
}

bool deadlines_overlap(const Deadline& a, const Deadline& b, std::chrono::milliseconds c) {
  return std::min(a.t_early, b.t_early) + a.t_duration + b.t_duration + c >
         std::max(a.t_finish, b.t_finish);
}

Plan calculate_assignments(const Model& model, const std::vector<BundleState>& state,
                           const std::vector<BundleId>& previous_order,
                           const std::vector<char>& previously_granted,
                           const PlanContext& context) {
  const std::size_t n = model.bundles().size();
  Plan plan;
  plan.time = context.now;
  plan.unavailable = context.unavailable;
  plan.bundle_granted.assign(n, 0);
  plan.resource_granted.assign(model.resources().size(), 0);
  plan.effective_priority.assign(n, 0);

  // Abb. 4.19 line 6: W_t = W_{t-1} ∪ R, new requests appended (in bundle order).
  std::vector<char> in_order(n, 0);
  plan.order.reserve(n);
  for (BundleId b : previous_order) {
    if (b < n && state[b].requested && !in_order[b]) {
      in_order[b] = 1;
      plan.order.push_back(b);
    }
  }
  for (BundleId b = 0; b < n; ++b) {
    if (state[b].requested && !in_order[b]) plan.order.push_back(b);
  }

  // Sort keys. A cycle is one element with its highest priority and earliest relative
  // deadline (seed §4.5.1).
  constexpr auto kNoDeadline = std::chrono::milliseconds::max();
  std::vector<std::chrono::milliseconds> rel(n, kNoDeadline);
  std::vector<char> boosted(n, 0);
  for (BundleId b : plan.order) {
    int prio = state[b].priority;
    auto d = state[b].deadline ? state[b].deadline->relative() : kNoDeadline;
    bool boost = state[b].boosted;
    for (BundleId m : model.cycle_of(b)) {
      if (!state[m].requested) continue;
      if (state[m].priority > prio || (state[m].priority == prio && state[m].boosted)) {
        prio = state[m].priority;
        boost = state[m].boosted;
      }
      if (state[m].deadline) d = std::min(d, state[m].deadline->relative());
    }
    plan.effective_priority[b] = prio;
    rel[b] = d;
    boosted[b] = boost;
  }
  auto held = [&](BundleId b) { return b < previously_granted.size() && previously_granted[b]; };
  // Abb. 4.19 step 2; stable, so equal bundles keep their place (no oscillation, §4.5.3).
  std::stable_sort(plan.order.begin(), plan.order.end(), [&](BundleId a, BundleId b) {
    if (plan.effective_priority[a] != plan.effective_priority[b]) {
      return plan.effective_priority[a] > plan.effective_priority[b];
    }
    if (boosted[a] != boosted[b]) return boosted[a] > boosted[b];
    if (rel[a] != rel[b]) return rel[a] < rel[b];
    return held(a) && !held(b);
  });

  // Abb. 4.19 step 3: greedy from the highest priority down; a bundle before its t_early waits
  // (§4.5.1), keeping its place for the plan at t_early.
  Assignment assignment(model, plan.unavailable);
  for (BundleId b : plan.order) {
    if (waits_for_t_early(state[b], context.now)) continue;
    if (assignment.try_grant(bundle_uses(model, b), b)) plan.bundle_granted[b] = 1;
  }
  plan.uses = assignment.take_uses();
  for (const auto& list : plan.uses) {
    for (const GrantedUse& g : list) {
      if (g.use.by == Use::By::kResource) plan.resource_granted[g.use.holder] = 1;
    }
  }
  // Bundles granted only through inheritance (a service applet's bundle) count as granted too.
  for (BundleId b = 0; b < n; ++b) {
    bool all = true;
    for (ResourceId r : model.bundle(b).resources) all = all && plan.resource_granted[r];
    plan.bundle_granted[b] = all;
  }

  // Overlapping deadlines within one priority (eq. 4.11), reported, not resolved (best effort).
  std::map<int, std::vector<BundleId>> by_priority;
  for (BundleId b : plan.order) {
    if (state[b].deadline) by_priority[plan.effective_priority[b]].push_back(b);
  }
  for (const auto& [prio, list] : by_priority) {
    for (std::size_t i = 0; i < list.size(); ++i) {
      for (std::size_t j = i + 1; j < list.size(); ++j) {
        if (deadlines_overlap(*state[list[i]].deadline, *state[list[j]].deadline,
                              context.context_switch)) {
          plan.deadline_overlaps.emplace_back(std::min(list[i], list[j]),
                                              std::max(list[i], list[j]));
        }
      }
    }
  }
  std::sort(plan.deadline_overlaps.begin(), plan.deadline_overlaps.end());
  return plan;
}

bool can_grant(const Model& model, const Plan& plan, ServiceId service, Access access) {
  Assignment assignment(model, plan.unavailable);
  for (const auto& list : plan.uses) {
    for (const GrantedUse& g : list) assignment.add_existing(g);
  }
  // A hypothetical holder that nobody else is: the service itself as its own user.
  return assignment.probe({Use{service, access, Use::By::kService, service}});
}

}  // namespace oscar::applets
