#include "oscar/applets/plan.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <span>

namespace oscar::applets {
namespace {

// One entry of the working set with its sort key (seed Abb. 4.19 step 2), kept together so that
// sorting touches one contiguous array instead of four arrays at random places.
struct Entry {
  int priority = 0;
  bool boosted = false;
  bool held = false;
  bool waits = false;  ///< t_early lies after the plan's time (§4.5.1)
  std::chrono::milliseconds relative{0};
  std::uint32_t position = 0;  ///< place in W_{t-1}, new requests after it in bundle order
  BundleId bundle = 0;
};

// Priority ↓, triggered first, relative deadline ↑ (EDF), held first, then the place in the
// previous working set: a total order, so std::sort gives what a stable sort of W_{t-1} gives.
bool before(const Entry& a, const Entry& b) {
  if (a.priority != b.priority) return a.priority > b.priority;
  if (a.boosted != b.boosted) return a.boosted;
  if (a.relative != b.relative) return a.relative < b.relative;
  if (a.held != b.held) return a.held;
  return a.position < b.position;
}

// Scratch memory of the plan, kept per thread from one plan to the next: a plan over 100 000
// bundles needs several megabytes of it, and fresh pages on every plan (the allocator returns
// large blocks to the system) cost more page faults than the plan itself.
struct Workspace {
  std::vector<GrantedUse> granted;
  std::vector<std::uint32_t> count;
  std::vector<char> exclusive, expanded, resource_used;
  std::vector<ServiceId> expanded_journal;
  std::vector<Entry> entries, run, aside;
  std::vector<char> in_order;
  std::vector<Use> walk;
  std::vector<std::uint32_t> walk_end;
};

Workspace& workspace() {
  thread_local Workspace w;
  return w;
}

// Who currently uses which service, with an undo journal so that a bundle whose closure fails
// half-way leaves no trace (all or nothing, seed Abb. 4.6 and 4.9). The uses are kept in one
// flat list in grant order (a list per service cost an allocation per service and plan, at
// random places); only their number and exclusiveness per service decide a grant.
class Assignment {
 public:
  Assignment(const Model& model, const std::vector<char>& unavailable, Workspace& w)
      : model_(model),
        unavailable_(unavailable),
        granted_(w.granted),
        count_(w.count),
        exclusive_(w.exclusive),
        expanded_(w.expanded),
        resource_used_(w.resource_used),
        expanded_journal_(w.expanded_journal) {
    granted_.clear();
    count_.assign(model.services().size(), 0);
    exclusive_.assign(model.services().size(), 0);
    expanded_.assign(model.services().size(), 0);
    resource_used_.assign(model.resources().size(), 0);
    expanded_journal_.clear();
  }

  void add_existing(const GrantedUse& g) {
    if (g.use.by == Use::By::kResource) resource_used_[g.use.holder] = 1;
    granted_.push_back(g);
    ++count_[g.use.service];
    if (g.use.access == Access::kExclusive) exclusive_[g.use.service] = 1;
    expanded_[g.use.service] = 1;
  }

  // Tries to grant `uses` rooted at `root` and everything they need; commits or rolls back.
  bool try_grant(std::span<const Use> uses, BundleId root) {
    const std::size_t mark = granted_.size();
    bool ok = true;
    for (const Use& u : uses) {
      if (!use(u, root) || !expand(u.service, root)) {
        ok = false;
        break;
      }
    }
    if (!ok) rollback(mark);
    expanded_journal_.clear();
    return ok;
  }

  bool probe(std::span<const Use> uses) {
    const std::size_t mark = granted_.size();
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

  // The uses per service, each in grant order.
  std::vector<std::vector<GrantedUse>> take_uses() {
    std::vector<std::vector<GrantedUse>> out(count_.size());
    for (ServiceId s = 0; s < count_.size(); ++s) out[s].reserve(count_[s]);
    for (const GrantedUse& g : granted_) out[g.use.service].push_back(g);
    return out;
  }

 private:
  // Abb. 4.21 steps 1–2: a service given exclusively admits nobody else; an exclusive use
  // admits nobody before it. A resource already in use is no new use (a service applet's
  // resource needed by two of its services); a service's own uses are added once, when it is
  // expanded, so they need no such check.
  bool use(const Use& u, BundleId root) {
    const bool by_resource = u.by == Use::By::kResource;
    if (by_resource && resource_used_[u.holder]) return true;
    if (u.service < unavailable_.size() && unavailable_[u.service]) return false;
    if (exclusive_[u.service]) return false;
    if (u.access == Access::kExclusive && count_[u.service] != 0) return false;
    if (by_resource) resource_used_[u.holder] = 1;
    granted_.push_back(GrantedUse{u, root});
    ++count_[u.service];
    if (u.access == Access::kExclusive) exclusive_[u.service] = 1;
    return true;
  }

  // Abb. 4.21 steps 3–4 and Abb. 4.19 lines 19–24: what a used service needs is used too, by
  // the service itself (configured dependencies) or by its service applet's resources.
  // Services already expanded need nothing new; this also ends the walk around a cycle.
  bool expand(ServiceId s, BundleId root) {
    if (expanded_[s]) return true;
    expanded_[s] = 1;
    expanded_journal_.push_back(s);
    for (const Use& u : model_.needs(s)) {
      if (!use(u, root) || !expand(u.service, root)) return false;
    }
    return true;
  }

  void rollback(std::size_t mark) {
    for (ServiceId s : expanded_journal_) expanded_[s] = 0;
    expanded_journal_.clear();
    while (granted_.size() > mark) {
      const Use& u = granted_.back().use;
      if (u.by == Use::By::kResource) resource_used_[u.holder] = 0;
      --count_[u.service];
      // An exclusive use is always a sole use: after removing any use, none is left exclusive.
      exclusive_[u.service] = 0;
      granted_.pop_back();
    }
  }

  const Model& model_;
  const std::vector<char>& unavailable_;
  std::vector<GrantedUse>& granted_;
  std::vector<std::uint32_t>& count_;
  std::vector<char>& exclusive_;
  std::vector<char>& expanded_;
  std::vector<char>& resource_used_;
  std::vector<ServiceId>& expanded_journal_;  // expanded by the bundle being tried
};

// Sorts the working set, which arrives in its previous order and so is sorted but for the
// bundles whose keys changed since the last plan (seed §4.5.3: plans are recomputed on every
// request, release, priority or deadline change). One pass keeps a sorted run and sets aside
// each entry that breaks it (or the run's last entry, if that is the one out of place); only
// those m entries are sorted, then merged back: O(n + m log m), O(n log n) at worst.
void sort_working_set(std::vector<Entry>& entries, Workspace& w) {
  std::vector<Entry>& run = w.run;
  std::vector<Entry>& aside = w.aside;
  run.clear();
  aside.clear();
  run.reserve(entries.size());
  for (const Entry& e : entries) {
    if (run.empty() || !before(e, run.back())) {
      run.push_back(e);
    } else if (run.size() >= 2 && !before(e, run[run.size() - 2])) {
      aside.push_back(run.back());  // the run's last entry moved down: set it aside instead
      run.back() = e;
    } else {
      aside.push_back(e);
    }
  }
  if (aside.empty()) return;
  std::sort(aside.begin(), aside.end(), before);
  std::merge(run.begin(), run.end(), aside.begin(), aside.end(), entries.begin(), before);
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

  // A cycle is one element with its highest priority (triggered first among equals) and earliest
  // relative deadline (seed §4.5.1), over its requested members: one pass over all bundles, then
  // one lookup per member (not a walk over the cycle per member, quadratic in its size).
  constexpr auto kNoDeadline = std::chrono::milliseconds::max();
  struct CycleKey {
    int priority = std::numeric_limits<int>::min();
    bool boosted = false;
    std::chrono::milliseconds relative = kNoDeadline;
  };
  std::vector<CycleKey> cycle_keys(model.cycle_count());
  for (BundleId b = 0; b < n && !cycle_keys.empty(); ++b) {
    const auto cycle = model.cycle_index(b);
    if (!cycle || !state[b].requested) continue;
    CycleKey& k = cycle_keys[*cycle];
    if (state[b].priority > k.priority) {
      k.priority = state[b].priority;
      k.boosted = state[b].boosted;
    } else if (state[b].priority == k.priority) {
      k.boosted = k.boosted || state[b].boosted;
    }
    if (state[b].deadline) k.relative = std::min(k.relative, state[b].deadline->relative());
  }

  // Abb. 4.19 line 6: W_t = W_{t-1} ∪ R, new requests appended (in bundle order).
  Workspace& w = workspace();
  std::vector<Entry>& entries = w.entries;
  entries.clear();
  std::vector<char>& in_order = w.in_order;
  in_order.assign(n, 0);
  auto add = [&](BundleId b) {
    const BundleState& st = state[b];
    in_order[b] = 1;
    Entry e;
    e.bundle = b;
    e.priority = st.priority;
    e.boosted = st.boosted;
    e.relative = st.deadline ? st.deadline->relative() : kNoDeadline;
    if (const auto cycle = model.cycle_index(b)) {
      const CycleKey& k = cycle_keys[*cycle];
      e.priority = k.priority;
      e.boosted = k.boosted;
      e.relative = k.relative;
    }
    e.held = b < previously_granted.size() && previously_granted[b];
    e.waits = waits_for_t_early(st, context.now);
    e.position = static_cast<std::uint32_t>(entries.size());
    plan.effective_priority[b] = e.priority;
    entries.push_back(e);
  };
  for (BundleId b : previous_order) {
    if (b < n && state[b].requested && !in_order[b]) add(b);
  }
  for (BundleId b = 0; b < n; ++b) {
    if (state[b].requested && !in_order[b]) add(b);
  }
  // Abb. 4.19 step 2; equal bundles keep their place (no oscillation, §4.5.3).
  sort_working_set(entries, w);
  plan.order.reserve(entries.size());
  for (const Entry& e : entries) plan.order.push_back(e.bundle);

  // What the walk needs, gathered in walk order first: the gathering loads are independent of
  // each other, so the processor overlaps them; the greedy walk then reads one array in order.
  std::vector<Use>& walk = w.walk;
  walk.clear();
  std::vector<std::uint32_t>& walk_end = w.walk_end;
  walk_end.resize(entries.size());
  for (std::size_t k = 0; k < entries.size(); ++k) {
    if (!entries[k].waits) {
      const auto uses = model.bundle_uses(entries[k].bundle);
      walk.insert(walk.end(), uses.begin(), uses.end());
    }
    walk_end[k] = static_cast<std::uint32_t>(walk.size());
  }

  // Abb. 4.19 step 3: greedy from the highest priority down; a bundle before its t_early waits
  // (§4.5.1), keeping its place for the plan at t_early.
  Assignment assignment(model, plan.unavailable, w);
  std::uint32_t begin = 0;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const std::span<const Use> uses(walk.data() + begin, walk_end[k] - begin);
    begin = walk_end[k];
    if (entries[k].waits) continue;
    if (assignment.try_grant(uses, entries[k].bundle)) plan.bundle_granted[entries[k].bundle] = 1;
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
    for (const Use& u : model.bundle_uses(b)) all = all && plan.resource_granted[u.holder];
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
  Assignment assignment(model, plan.unavailable, workspace());
  for (const auto& list : plan.uses) {
    for (const GrantedUse& g : list) assignment.add_existing(g);
  }
  // A hypothetical holder that nobody else is: the service itself as its own user.
  const Use probe{service, access, Use::By::kService, service};
  return assignment.probe(std::span<const Use>(&probe, 1));
}

}  // namespace oscar::applets
