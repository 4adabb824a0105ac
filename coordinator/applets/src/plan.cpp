#include "oscar/applets/plan.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>

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

// What the plan knows of one service while it walks, in one place: a grant looks at all of it.
struct ServiceUse {
  std::uint32_t count : 30 = 0;     ///< uses granted (each by another resource or service)
  std::uint32_t exclusive : 1 = 0;  ///< one of them (then the only one) is exclusive
  std::uint32_t expanded : 1 = 0;   ///< what it needs is used too
};

// Scratch memory of the plan, kept per thread from one plan to the next: a plan over 100 000
// bundles needs several megabytes of it, and fresh pages on every plan (the allocator returns
// large blocks to the system) cost more page faults than the plan itself.
struct Workspace {
  std::vector<GrantedUse> granted;
  std::vector<ServiceUse> service;
  std::vector<char> resource_used;
  std::vector<ServiceId> expanded_journal;
  std::vector<Entry> entries, aside;
  std::vector<char> waits;
  std::vector<std::span<const Use>> walk;
  std::vector<std::uint32_t> place;
  std::vector<std::pair<int, BundleId>> timed;
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
        service_(w.service),
        resource_used_(w.resource_used),
        expanded_journal_(w.expanded_journal) {
    granted_.clear();
    service_.assign(model.services().size(), ServiceUse{});
    resource_used_.assign(model.resources().size(), 0);
    expanded_journal_.clear();
  }

  void add_existing(const GrantedUse& g) {
    if (g.use.by == Use::By::kResource) resource_used_[g.use.holder] = 1;
    granted_.push_back(g);
    ServiceUse& s = service_[g.use.service];
    ++s.count;
    if (g.use.access == Access::kExclusive) s.exclusive = true;
    s.expanded = true;
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

  // Fetches what granting `u` looks at first into the cache.
  void prefetch(const Use& u) const {
    __builtin_prefetch(&service_[u.service]);
    if (u.by == Use::By::kResource) __builtin_prefetch(&resource_used_[u.holder]);
  }

  // Per resource: whether a granted use is by it.
  const std::vector<char>& resources_used() const { return resource_used_; }

  // Every use granted so far, in grant order.
  const std::vector<GrantedUse>& granted() const { return granted_; }

 private:
  // Abb. 4.21 steps 1–2: a service given exclusively admits nobody else; an exclusive use
  // admits nobody before it. A resource already in use is no new use (a service applet's
  // resource needed by two of its services); a service's own uses are added once, when it is
  // expanded, so they need no such check.
  bool use(const Use& u, BundleId root) {
    const bool by_resource = u.by == Use::By::kResource;
    if (by_resource && resource_used_[u.holder]) return true;
    if (u.service < unavailable_.size() && unavailable_[u.service]) return false;
    ServiceUse& s = service_[u.service];
    if (s.exclusive) return false;
    if (u.access == Access::kExclusive && s.count != 0) return false;
    if (by_resource) resource_used_[u.holder] = 1;
    granted_.push_back(GrantedUse{u, root});
    ++s.count;
    if (u.access == Access::kExclusive) s.exclusive = true;
    return true;
  }

  // Abb. 4.21 steps 3–4 and Abb. 4.19 lines 19–24: what a used service needs is used too, by
  // the service itself (configured dependencies) or by its service applet's resources.
  // Services already expanded need nothing new; this also ends the walk around a cycle.
  bool expand(ServiceId s, BundleId root) {
    if (service_[s].expanded) return true;
    service_[s].expanded = true;
    expanded_journal_.push_back(s);
    for (const Use& u : model_.needs(s)) {
      if (!use(u, root) || !expand(u.service, root)) return false;
    }
    return true;
  }

  void rollback(std::size_t mark) {
    for (ServiceId s : expanded_journal_) service_[s].expanded = false;
    expanded_journal_.clear();
    while (granted_.size() > mark) {
      const Use& u = granted_.back().use;
      if (u.by == Use::By::kResource) resource_used_[u.holder] = 0;
      ServiceUse& s = service_[u.service];
      --s.count;
      // An exclusive use is always a sole use: after removing any use, none is left exclusive.
      s.exclusive = false;
      granted_.pop_back();
    }
  }

  const Model& model_;
  const std::vector<char>& unavailable_;
  std::vector<GrantedUse>& granted_;
  std::vector<ServiceUse>& service_;
  std::vector<char>& resource_used_;
  std::vector<ServiceId>& expanded_journal_;  // expanded by the bundle being tried
};

// Sorts the working set, which arrives in its previous order and so is sorted but for the
// bundles whose keys changed since the last plan (seed §4.5.3: plans are recomputed on every
// request, release, priority or deadline change). One pass keeps a sorted run in place and sets
// aside each entry that breaks it (or the run's last entry, if that is the one out of place);
// only those m entries are sorted, then merged with the run: O(n + m log n), O(n log n) at
// worst. The merge writes only what the walk needs, not the entries themselves: the bundles in
// order, whether each waits, and where each one's uses are (looked up here, in a loop of
// independent loads, rather than in the walk, where each lookup would stall the grants).
void sort_working_set(const Model& model, std::vector<Entry>& entries, Workspace& w,
                      std::vector<BundleId>& order, std::vector<char>& waits,
                      std::vector<std::span<const Use>>& walk) {
  std::vector<Entry>& aside = w.aside;
  aside.clear();
  std::size_t run = 0;  // the run is entries[0, run), built in place: run <= k at entry k
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const Entry e = entries[k];
    if (run == 0 || !before(e, entries[run - 1])) {
      if (run != k) entries[run] = e;
      ++run;
    } else if (run >= 2 && !before(e, entries[run - 2])) {
      aside.push_back(entries[run - 1]);  // the run's last entry moved down: set it aside instead
      entries[run - 1] = e;
    } else {
      aside.push_back(e);
    }
  }
  std::sort(aside.begin(), aside.end(), before);
  order.resize(entries.size());
  waits.resize(entries.size());
  walk.resize(entries.size());
  // Each set-aside entry's place in the run by binary search, the run's entries before it
  // copied without comparing: O(n + m log n).
  std::size_t k = 0;
  auto put = [&](const Entry& e) {
    order[k] = e.bundle;
    waits[k] = e.waits;
    walk[k] = model.bundle_uses(e.bundle);
    ++k;
  };
  const auto run_end = entries.begin() + static_cast<std::ptrdiff_t>(run);
  auto i = entries.begin();
  for (const Entry& e : aside) {
    const auto place = std::lower_bound(i, run_end, e, before);
    for (; i != place; ++i) put(*i);
    put(e);
  }
  for (; i != run_end; ++i) put(*i);
}

}  // namespace

UsesByService::UsesByService(std::size_t services, const std::vector<GrantedUse>& in_grant_order)
    : begin_(services + 1, 0), uses_(in_grant_order.size()) {
  // A counting sort by service: stable, so each service's uses stay in grant order.
  for (const GrantedUse& g : in_grant_order) {
    if (g.use.service >= services) {
      throw std::invalid_argument("plan: a use of service " + std::to_string(g.use.service) +
                                  " among " + std::to_string(services) + " services");
    }
    ++begin_[g.use.service + 1];
  }
  for (std::size_t s = 0; s < services; ++s) begin_[s + 1] += begin_[s];
  std::vector<std::uint32_t> next(begin_.begin(), begin_.end() - 1);
  for (const GrantedUse& g : in_grant_order) uses_[next[g.use.service]++] = g;
}

std::span<const GrantedUse> UsesByService::at(ServiceId service) const {
  if (service >= size()) {
    throw std::out_of_range("plan: unknown service " + std::to_string(service) + " (the plan has " +
                            std::to_string(size()) + ")");
  }
  return (*this)[service];
}

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
  // Every pass over per-bundle data goes in bundle order, so that it reads memory one line after
  // the next: only the greedy walk goes in priority order, and it reads the working set in order
  // and each bundle's uses ahead of time. A pass in priority order over 100 000 bundles reads
  // every array at a new cache line (and often a new page) per bundle, which made the plan grow
  // 30-45x from 10 000 to 100 000 bundles while all arrays fitted the second-level cache at
  // 10 000 and none did at 100 000.
  const std::size_t n = model.bundles().size();
  Plan plan;
  plan.time = context.now;
  plan.unavailable = context.unavailable;
  plan.bundle_granted.assign(n, 0);
  plan.effective_priority.assign(n, 0);

  // A cycle is one element with its highest priority (triggered first among equals) and earliest
  // relative deadline (seed §4.5.1), over its requested members: one pass over each cycle's
  // members, then one lookup per member (not a walk over the cycle per member, quadratic in its
  // size).
  constexpr auto kNoDeadline = std::chrono::milliseconds::max();
  struct CycleKey {
    int priority = std::numeric_limits<int>::min();
    bool boosted = false;
    std::chrono::milliseconds relative = kNoDeadline;
  };
  std::vector<CycleKey> cycle_keys(model.cycle_count());
  for (std::size_t c = 0; c < cycle_keys.size(); ++c) {
    CycleKey& k = cycle_keys[c];
    for (BundleId b : model.cycle_members(c)) {
      if (!state[b].requested) continue;
      if (state[b].priority > k.priority) {
        k.priority = state[b].priority;
        k.boosted = state[b].boosted;
      } else if (state[b].priority == k.priority) {
        k.boosted = k.boosted || state[b].boosted;
      }
      if (state[b].deadline) k.relative = std::min(k.relative, state[b].deadline->relative());
    }
  }

  // Abb. 4.19 line 6: W_t = W_{t-1} ∪ R, new requests appended (in bundle order). Each requested
  // bundle's place in W_t first (a small array per bundle, read and written in W_{t-1}'s order),
  // then its entry is written straight to that place in one pass in bundle order. The first
  // pass also notes the bundles with a deadline, for the overlap check at the end.
  Workspace& w = workspace();
  constexpr std::uint32_t kNotRequested = ~std::uint32_t{0};
  constexpr std::uint32_t kNoPlace = kNotRequested - 1;
  std::vector<std::uint32_t>& place = w.place;
  place.resize(n);
  std::vector<std::pair<int, BundleId>>& timed = w.timed;
  timed.clear();
  std::uint32_t requested = 0;
  for (BundleId b = 0; b < n; ++b) {
    place[b] = kNotRequested;
    if (!state[b].requested) continue;
    place[b] = kNoPlace;
    ++requested;
    if (state[b].deadline) timed.emplace_back(0, b);
  }
  std::uint32_t size = 0;
  for (BundleId b : previous_order) {
    if (b < n && place[b] == kNoPlace) place[b] = size++;
  }
  std::vector<Entry>& entries = w.entries;
  entries.resize(requested);
  constexpr BundleId kWriteAhead = 16;
  for (BundleId b = 0; b < n; ++b) {
    // The places are at random in the entries: the line of one some bundles on is fetched
    // for writing while this one is made, instead of the writes queueing up for their lines.
    if (b + kWriteAhead < n && place[b + kWriteAhead] < kNoPlace) {
      __builtin_prefetch(&entries[place[b + kWriteAhead]], 1);
    }
    if (place[b] == kNotRequested) continue;
    if (place[b] == kNoPlace) place[b] = size++;
    const BundleState& st = state[b];
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
    e.position = place[b];
    plan.effective_priority[b] = e.priority;
    entries[place[b]] = e;
  }
  // Abb. 4.19 step 2; equal bundles keep their place (no oscillation, §4.5.3).
  std::vector<char>& waits = w.waits;
  std::vector<std::span<const Use>>& walk = w.walk;
  sort_working_set(model, entries, w, plan.order, waits, walk);

  // Abb. 4.19 step 3: greedy from the highest priority down; a bundle before its t_early waits
  // (§4.5.1), keeping its place for the plan at t_early. The walk jumps between bundles and
  // services: the uses of a bundle 2d places ahead, and the state of the first service of the
  // bundle d places ahead, are fetched into the cache while this one is tried, instead of being
  // waited for in turn.
  Assignment assignment(model, plan.unavailable, w);
  constexpr std::size_t kAhead = 8;
  const std::vector<BundleId>& order = plan.order;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k + 2 * kAhead < order.size()) __builtin_prefetch(walk[k + 2 * kAhead].data());
    if (k + kAhead < order.size() && !walk[k + kAhead].empty()) {
      assignment.prefetch(walk[k + kAhead].front());
    }
    if (waits[k]) continue;
    assignment.try_grant(walk[k], order[k]);
  }
  plan.uses = UsesByService(model.services().size(), assignment.granted());
  plan.resource_granted = assignment.resources_used();
  // A bundle is granted when all its resources are: also one granted only through inheritance
  // (a service applet's bundle).
  for (BundleId b = 0; b < n; ++b) {
    bool all = true;
    for (const Use& u : model.bundle_uses(b)) all = all && plan.resource_granted[u.holder];
    plan.bundle_granted[b] = all;
  }

  // Overlapping deadlines within one priority (eq. 4.11), reported, not resolved (best effort).
  // The requested bundles with a deadline, grouped by priority; the check is symmetric and the
  // pairs are sorted at the end, so the order within a group does not matter.
  for (auto& [priority, b] : timed) priority = plan.effective_priority[b];
  std::sort(timed.begin(), timed.end());
  for (std::size_t group = 0; group < timed.size();) {
    std::size_t group_end = group;
    while (group_end < timed.size() && timed[group_end].first == timed[group].first) ++group_end;
    for (std::size_t i = group; i < group_end; ++i) {
      for (std::size_t j = i + 1; j < group_end; ++j) {
        const BundleId a = timed[i].second, b = timed[j].second;
        if (deadlines_overlap(*state[a].deadline, *state[b].deadline, context.context_switch)) {
          plan.deadline_overlaps.emplace_back(a, b);  // a < b: sorted by bundle within a group
        }
      }
    }
    group = group_end;
  }
  std::sort(plan.deadline_overlaps.begin(), plan.deadline_overlaps.end());
  return plan;
}

bool can_grant(const Model& model, const Plan& plan, ServiceId service, Access access) {
  Assignment assignment(model, plan.unavailable, workspace());
  for (const GrantedUse& g : plan.uses.all()) assignment.add_existing(g);
  // A hypothetical holder that nobody else is: the service itself as its own user.
  const Use probe{service, access, Use::By::kService, service};
  return assignment.probe(std::span<const Use>(&probe, 1));
}

}  // namespace oscar::applets
