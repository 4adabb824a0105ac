// The plan (calculate_assignments) against a straightforward reference implementation of seed 000
// Abb. 4.19–4.21 on randomised models and states: the plan is optimised for large working sets
// (its own sort, flat tables, prefetching), and this checks that every part of its result is what
// the plain algorithm gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "oscar/applets/plan.hpp"

namespace oscar::applets {
namespace {

using std::chrono::milliseconds;

// Built with += : GCC 12 warns falsely (-Wrestrict) on "literal" + std::to_string at -O3.
std::string name_of(const char* prefix, long i) {
  std::string s = prefix;
  s += std::to_string(i);
  return s;
}

struct Key {
  int priority = 0;
  bool boosted = false;
  milliseconds relative = milliseconds::max();
};

// The sort key of a requested bundle: its own, or its cycle's (highest priority, triggered if a
// member of that priority is, earliest relative deadline over the requested members).
Key key_of(const Model& m, const std::vector<BundleState>& state, BundleId b) {
  const auto& cycle = m.cycle_of(b);
  if (cycle.empty()) {
    Key k{state[b].priority, state[b].boosted, milliseconds::max()};
    if (state[b].deadline) k.relative = state[b].deadline->relative();
    return k;
  }
  Key k;
  k.priority = std::numeric_limits<int>::min();
  for (BundleId c : cycle) {
    if (state[c].requested) k.priority = std::max(k.priority, state[c].priority);
  }
  for (BundleId c : cycle) {
    if (!state[c].requested) continue;
    if (state[c].priority == k.priority && state[c].boosted) k.boosted = true;
    if (state[c].deadline) k.relative = std::min(k.relative, state[c].deadline->relative());
  }
  return k;
}

// What is granted so far; copied for every bundle tried, kept only if the whole closure fits.
struct RefState {
  std::vector<std::vector<GrantedUse>> uses;
  std::set<ResourceId> used_resources;
  std::set<ServiceId> expanded;
};

struct Reference {
  const Model& m;
  const std::vector<char>& unavailable;

  bool use(RefState& st, const Use& u, BundleId root) const {
    if (u.by == Use::By::kResource && st.used_resources.count(u.holder)) return true;
    if (u.service < unavailable.size() && unavailable[u.service]) return false;
    auto& list = st.uses[u.service];
    for (const GrantedUse& g : list) {
      if (g.use.access == Access::kExclusive) return false;
    }
    if (u.access == Access::kExclusive && !list.empty()) return false;
    if (u.by == Use::By::kResource) st.used_resources.insert(u.holder);
    list.push_back(GrantedUse{u, root});
    return true;
  }

  // What a service needs, from the model's declarations: its configured dependencies, then all
  // resources of its service applet.
  std::vector<Use> needs(ServiceId s) const {
    std::vector<Use> out;
    for (const Dependency& d : m.service(s).dependencies) {
      out.push_back(Use{d.service, d.access, Use::By::kService, s});
    }
    if (const auto provider = m.service(s).provider) {
      for (ResourceId r : m.applet(*provider).resources) {
        out.push_back(Use{m.resource(r).service, m.resource(r).access, Use::By::kResource, r});
      }
    }
    return out;
  }

  bool expand(RefState& st, ServiceId s, BundleId root) const {
    if (!st.expanded.insert(s).second) return true;
    for (const Use& u : needs(s)) {
      if (!use(st, u, root) || !expand(st, u.service, root)) return false;
    }
    return true;
  }
};

// The reference's plan: a Plan with the uses per service kept apart, as lists.
struct ReferencePlan {
  Plan plan;
  std::vector<std::vector<GrantedUse>> uses;
};

ReferencePlan reference_plan(const Model& m, const std::vector<BundleState>& state,
                             const std::vector<BundleId>& previous_order,
                             const std::vector<char>& previously_granted,
                             const PlanContext& context) {
  const std::size_t n = m.bundles().size();
  ReferencePlan out;
  Plan& p = out.plan;
  p.time = context.now;
  p.unavailable = context.unavailable;
  p.effective_priority.assign(n, 0);
  std::vector<char> in(n, 0);
  for (BundleId b : previous_order) {
    if (b < n && state[b].requested && !in[b]) {
      in[b] = 1;
      p.order.push_back(b);
    }
  }
  for (BundleId b = 0; b < n; ++b) {
    if (state[b].requested && !in[b]) p.order.push_back(b);
  }
  std::vector<Key> keys(n);
  for (BundleId b : p.order) {
    keys[b] = key_of(m, state, b);
    p.effective_priority[b] = keys[b].priority;
  }
  auto held = [&](BundleId b) { return b < previously_granted.size() && previously_granted[b]; };
  std::stable_sort(p.order.begin(), p.order.end(), [&](BundleId a, BundleId b) {
    if (keys[a].priority != keys[b].priority) return keys[a].priority > keys[b].priority;
    if (keys[a].boosted != keys[b].boosted) return keys[a].boosted;
    if (keys[a].relative != keys[b].relative) return keys[a].relative < keys[b].relative;
    return held(a) && !held(b);
  });

  const Reference ref{m, context.unavailable};
  RefState granted;
  granted.uses.resize(m.services().size());
  for (BundleId b : p.order) {
    if (waits_for_t_early(state[b], context.now)) continue;
    RefState trial = granted;
    bool ok = true;
    for (ResourceId r : m.bundle(b).resources) {
      const Use u{m.resource(r).service, m.resource(r).access, Use::By::kResource, r};
      if (!ref.use(trial, u, b) || !ref.expand(trial, u.service, b)) {
        ok = false;
        break;
      }
    }
    if (ok) granted = std::move(trial);
  }
  out.uses = granted.uses;
  p.resource_granted.assign(m.resources().size(), 0);
  for (ResourceId r : granted.used_resources) p.resource_granted[r] = 1;
  p.bundle_granted.assign(n, 0);
  for (BundleId b = 0; b < n; ++b) {
    const auto& rs = m.bundle(b).resources;
    p.bundle_granted[b] =
        std::all_of(rs.begin(), rs.end(), [&](ResourceId r) { return p.resource_granted[r]; });
  }
  for (BundleId a = 0; a < n; ++a) {
    for (BundleId b = a + 1; b < n; ++b) {
      if (!state[a].requested || !state[b].requested || !state[a].deadline || !state[b].deadline ||
          p.effective_priority[a] != p.effective_priority[b]) {
        continue;
      }
      if (deadlines_overlap(*state[a].deadline, *state[b].deadline, context.context_switch)) {
        p.deadline_overlaps.emplace_back(a, b);
      }
    }
  }
  return out;
}

using UseKey = std::tuple<ServiceId, Access, Use::By, std::uint32_t, BundleId>;

std::vector<UseKey> keys_of(std::span<const GrantedUse> uses) {
  std::vector<UseKey> out;
  for (const GrantedUse& g : uses) {
    out.emplace_back(g.use.service, g.use.access, g.use.by, g.use.holder, g.root);
  }
  return out;
}

void expect_same(const Plan& got, const ReferencePlan& ref, const std::string& where) {
  const Plan& want = ref.plan;
  EXPECT_EQ(got.time, want.time) << where;
  EXPECT_EQ(got.order, want.order) << where;
  EXPECT_EQ(got.bundle_granted, want.bundle_granted) << where;
  EXPECT_EQ(got.resource_granted, want.resource_granted) << where;
  ASSERT_EQ(got.uses.size(), ref.uses.size()) << where;
  for (ServiceId s = 0; s < ref.uses.size(); ++s) {
    EXPECT_EQ(keys_of(got.uses[s]), keys_of(ref.uses[s])) << where << " service " << s;
  }
  EXPECT_EQ(got.deadline_overlaps, want.deadline_overlaps) << where;
  EXPECT_EQ(got.effective_priority, want.effective_priority) << where;
  EXPECT_EQ(got.unavailable, want.unavailable) << where;
}

// Services with configured dependencies (cycles among them too), applets of which some provide a
// service (closing cycles through their resources), bundles of one to three resources.
Model random_model(std::mt19937& rng, int services, int applets) {
  Model m;
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  for (int s = 0; s < services; ++s) m.add_service(name_of("S", s), pick(6) == 0);
  for (int s = 0; s < services; ++s) {
    if (pick(3) != 0) continue;
    const auto dep = static_cast<ServiceId>(pick(services));
    if (dep == static_cast<ServiceId>(s)) continue;
    m.add_dependency(
        static_cast<ServiceId>(s), dep,
        m.service(dep).exclusive_only || pick(2) ? Access::kExclusive : Access::kShared);
  }
  for (int a = 0; a < applets; ++a) {
    const AppletId id = m.add_applet(name_of("A", a));
    if (pick(4) == 0) {
      const auto s = static_cast<ServiceId>(pick(services));
      if (!m.service(s).provider) m.provide(id, s);
    }
    const int bundles = 1 + pick(2);
    for (int b = 0; b < bundles; ++b) {
      std::vector<std::pair<ServiceId, Access>> res;
      const int size = 1 + pick(3);
      for (int k = 0; k < size; ++k) {
        const auto s = static_cast<ServiceId>(pick(services));
        if (std::any_of(res.begin(), res.end(), [&](auto& r) { return r.first == s; })) continue;
        res.emplace_back(
            s, m.service(s).exclusive_only || pick(2) ? Access::kExclusive : Access::kShared);
      }
      m.add_bundle(id, name_of("b", b), res, kPriorityLow + 50 * pick(4));
    }
  }
  return m;
}

// A chain of plans, each made from the previous one's order and grants, with random changes in
// between: requests and releases, priorities (few levels, so ties are common), triggers,
// deadlines (some with an earliest start after the plan's time), unavailable services, and a
// previous order with unknown and repeated bundles in it.
void run_chain(unsigned seed, int services, int applets, int plans) {
  std::mt19937 rng(seed);
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  const Model m = random_model(rng, services, applets);
  const auto n = static_cast<int>(m.bundles().size());
  std::vector<BundleState> state(static_cast<std::size_t>(n));
  for (int b = 0; b < n; ++b) state[b].priority = m.bundle(static_cast<BundleId>(b)).priority;
  Plan previous;
  for (int k = 0; k < plans; ++k) {
    const int changes = 1 + pick(k % 5 == 0 ? n : 4);
    for (int c = 0; c < changes; ++c) {
      BundleState& st = state[pick(n)];
      switch (pick(6)) {
        case 0:
        case 1:
          st.requested = !st.requested;
          break;
        case 2:
          st.priority = kPriorityLow + 50 * pick(4);
          break;
        case 3:
          st.boosted = !st.boosted;
          break;
        case 4: {
          if (st.deadline) {
            st.deadline.reset();
          } else {
            const milliseconds early{pick(60)};
            const milliseconds duration{1 + pick(20)};
            st.deadline = Deadline{early, duration, early + duration + milliseconds{pick(40)}};
          }
          break;
        }
        default:
          st.requested = true;
          break;
      }
    }
    PlanContext context;
    context.now = milliseconds{10 * k % 50};
    context.context_switch = milliseconds{pick(5)};
    if (pick(4) == 0) {
      context.unavailable.assign(static_cast<std::size_t>(services), 0);
      context.unavailable[pick(services)] = 1;
    }
    std::vector<BundleId> previous_order = previous.order;
    if (pick(5) == 0 && !previous_order.empty()) {
      previous_order.push_back(previous_order.front());                             // repeated
      previous_order.insert(previous_order.begin(), static_cast<BundleId>(n + 3));  // unknown
    }
    const Plan got =
        calculate_assignments(m, state, previous_order, previous.bundle_granted, context);
    const ReferencePlan want =
        reference_plan(m, state, previous_order, previous.bundle_granted, context);
    expect_same(got, want, "seed " + std::to_string(seed) + " plan " + std::to_string(k));
    if (::testing::Test::HasFailure()) return;
    previous = got;
  }
}

TEST(PlanReference, SmallRandomModelsGiveTheReferencePlan) {
  for (unsigned seed = 1; seed <= 300; ++seed) {
    std::mt19937 size_rng(seed);
    run_chain(seed, 3 + static_cast<int>(size_rng() % 10), 2 + static_cast<int>(size_rng() % 12),
              25);
    if (HasFailure()) return;
  }
}

TEST(PlanReference, LargeRandomModelsGiveTheReferencePlan) {
  // Hundreds of bundles: long sorted runs with few entries set aside, and many at once.
  for (unsigned seed = 1; seed <= 4; ++seed) run_chain(1000 + seed, 150, 400, 30);
}

TEST(PlanUses, KeepEachServicesUsesInGrantOrder) {
  const auto use = [](ServiceId s, std::uint32_t holder, BundleId root) {
    return GrantedUse{Use{s, Access::kShared, Use::By::kResource, holder}, root};
  };
  const UsesByService uses(3, {use(2, 7, 1), use(0, 3, 2), use(2, 4, 3), use(0, 9, 4)});
  ASSERT_EQ(uses.size(), 3u);
  ASSERT_EQ(uses[0].size(), 2u);
  EXPECT_EQ(uses[0][0].use.holder, 3u);
  EXPECT_EQ(uses[0][1].use.holder, 9u);
  EXPECT_TRUE(uses[1].empty());
  ASSERT_EQ(uses.at(2).size(), 2u);
  EXPECT_EQ(uses.at(2)[0].root, 1u);
  EXPECT_EQ(uses.at(2)[1].root, 3u);
  EXPECT_EQ(uses.all().size(), 4u);
}

TEST(PlanUses, RejectAnUnknownService) {
  const GrantedUse beyond{Use{5, Access::kShared, Use::By::kService, 0}, 0};
  try {
    UsesByService(2, {beyond});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "plan: a use of service 5 among 2 services");
  }
  const UsesByService uses(2, {});
  try {
    (void)uses.at(2);
    FAIL() << "no exception";
  } catch (const std::out_of_range& e) {
    EXPECT_STREQ(e.what(), "plan: unknown service 2 (the plan has 2)");
  }
}

}  // namespace
}  // namespace oscar::applets
