// Randomized runs (fixed seeds) checking the scheduler's invariants after every plan.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <set>
#include <tuple>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {
namespace {

// Built with += : GCC 12 warns falsely (-Wrestrict) on "literal" + std::to_string at -O3.
std::string name_of(const char* prefix, long i) {
  std::string s = prefix;
  s += std::to_string(i);
  return s;
}

struct ClosureUse {
  ServiceId service;
  Access access;
  std::uint64_t holder;
};

std::uint64_t holder_key(const Use& u) {
  return (std::uint64_t{u.by == Use::By::kService} << 32) | u.holder;
}

// Everything granting `bundle` would use, computed independently of the planner.
std::vector<ClosureUse> closure_of(const Model& m, BundleId bundle) {
  std::vector<ClosureUse> out;
  std::set<ServiceId> expanded;
  std::vector<ServiceId> to_visit;
  for (ResourceId r : m.bundle(bundle).resources) {
    const Use u{m.resource(r).service, m.resource(r).access, Use::By::kResource, r};
    out.push_back({u.service, u.access, holder_key(u)});
    to_visit.push_back(u.service);
  }
  while (!to_visit.empty()) {
    const ServiceId s = to_visit.back();
    to_visit.pop_back();
    if (!expanded.insert(s).second) continue;
    for (const Use& u : m.needs(s)) {
      out.push_back({u.service, u.access, holder_key(u)});
      to_visit.push_back(u.service);
    }
  }
  return out;
}

bool clash(const ClosureUse& a, const ClosureUse& b) {
  return a.service == b.service && a.holder != b.holder &&
         (a.access == Access::kExclusive || b.access == Access::kExclusive);
}

Model random_model(std::mt19937& rng) {
  Model m;
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  const int services = 4 + pick(8);
  for (int s = 0; s < services; ++s) m.add_service(name_of("S", s), pick(5) == 0);
  for (int s = 1; s < services; ++s) {
    if (pick(4) == 0) {
      const auto dep = static_cast<ServiceId>(pick(s));  // acyclic configured dependencies
      m.add_dependency(
          s, dep, m.service(dep).exclusive_only || pick(2) ? Access::kExclusive : Access::kShared);
    }
  }
  const int applets = 2 + pick(6);
  for (int a = 0; a < applets; ++a) {
    const AppletId id = m.add_applet(name_of("A", a));
    if (pick(3) == 0) {
      const auto s = static_cast<ServiceId>(pick(services));
      if (!m.service(s).provider) m.provide(id, s);  // may close cycles through resources
    }
    const int bundles = 1 + pick(3);
    for (int b = 0; b < bundles; ++b) {
      std::vector<std::pair<ServiceId, Access>> res;
      const int size = 1 + pick(3);
      for (int k = 0; k < size; ++k) {
        const auto s = static_cast<ServiceId>(pick(services));
        if (std::any_of(res.begin(), res.end(), [&](auto& p) { return p.first == s; })) continue;
        res.emplace_back(
            s, m.service(s).exclusive_only || pick(2) ? Access::kExclusive : Access::kShared);
      }
      m.add_bundle(id, name_of("b", b), res, kPriorityLow + 50 * pick(7));
    }
  }
  return m;
}

void check_plan(const Scheduler& s, const std::string& where) {
  const Model& m = s.model();
  const Plan& p = s.plan();
  // Never two exclusive holders; never a shared holder beside an exclusive one.
  for (ServiceId id = 0; id < m.services().size(); ++id) {
    const auto& uses = p.uses[id];
    const auto excl = std::count_if(uses.begin(), uses.end(), [](const GrantedUse& g) {
      return g.use.access == Access::kExclusive;
    });
    ASSERT_TRUE(excl == 0 || uses.size() == 1) << where << " service " << m.service(id).name;
    // A service is granted only with what it needs (configured and service-applet resources).
    if (!uses.empty()) {
      for (const Use& need : m.needs(id)) {
        const auto& nu = p.uses[need.service];
        ASSERT_TRUE(
            std::any_of(nu.begin(), nu.end(),
                        [&](const GrantedUse& g) { return holder_key(g.use) == holder_key(need); }))
            << where << " service " << m.service(id).name << " lacks a dependency";
      }
    }
  }
  for (BundleId b = 0; b < m.bundles().size(); ++b) {
    // Bundles all or nothing.
    const auto& rs = m.bundle(b).resources;
    const auto granted = std::count_if(rs.begin(), rs.end(),
                                       [&](ResourceId r) { return p.resource_granted[r] != 0; });
    ASSERT_TRUE(granted == 0 || granted == static_cast<long>(rs.size())) << where;
    // Cycles all or nothing.
    for (BundleId c : m.cycle_of(b)) {
      ASSERT_EQ(p.bundle_granted[b], p.bundle_granted[c]) << where << " cycle split";
    }
    // A blocked request is blocked by something of at least its priority (or by itself).
    if (s.requested(b) && !p.bundle_granted[b]) {
      const auto mine = closure_of(m, b);
      bool self = false;
      for (std::size_t i = 0; i < mine.size(); ++i) {
        for (std::size_t j = 0; j < i; ++j) self = self || clash(mine[i], mine[j]);
      }
      bool by_higher = false;
      bool unavailable = false;  // needs a service whose service applet crashed
      for (const ClosureUse& u : mine) {
        unavailable = unavailable || !s.available(u.service);
        for (const GrantedUse& g : p.uses[u.service]) {
          const ClosureUse other{g.use.service, g.use.access, holder_key(g.use)};
          if (clash(u, other) && p.effective_priority[g.root] >= p.effective_priority[b]) {
            by_higher = true;
          }
        }
      }
      ASSERT_TRUE(self || by_higher || unavailable)
          << where << " bundle " << b << " blocked by lower priority";
    }
  }
  // What is in use right now never clashes (hand-over waits for the release).
  std::vector<std::pair<BundleId, std::vector<ClosureUse>>> active;
  for (BundleId b = 0; b < m.bundles().size(); ++b) {
    if (s.active(b)) active.emplace_back(b, closure_of(m, b));
  }
  for (std::size_t i = 0; i < active.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      for (const auto& u : active[i].second) {
        for (const auto& v : active[j].second) {
          ASSERT_FALSE(clash(u, v)) << where << " active bundles " << active[i].first << " and "
                                    << active[j].first << " clash on " << m.service(u.service).name;
        }
      }
    }
  }
}

// A lower-priority holder never keeps a service a higher-priority request could get, outside the
// bounded reassignment window: a planned bundle waits only for holders being revoked (never for
// one the plan still grants), and never longer than `bound`.
void check_no_lower_holder_keeps(const Scheduler& s,
                                 std::vector<std::optional<milliseconds>>& waiting_since,
                                 milliseconds bound, const std::string& where) {
  const Model& m = s.model();
  const Plan& p = s.plan();
  for (BundleId h = 0; h < m.bundles().size(); ++h) {
    if (!p.bundle_granted[h] || s.active(h)) {
      waiting_since[h].reset();
      continue;
    }
    if (!waiting_since[h]) waiting_since[h] = s.now();
    ASSERT_LE(s.now() - *waiting_since[h], bound) << where << " bundle " << h << " kept waiting";
    const auto mine = closure_of(m, h);
    for (BundleId l = 0; l < m.bundles().size(); ++l) {
      if (l == h || !s.active(l)) continue;
      bool clashes = false;
      for (const auto& u : mine) {
        for (const auto& v : closure_of(m, l)) clashes = clashes || clash(u, v);
      }
      if (!clashes) continue;
      ASSERT_FALSE(p.bundle_granted[l]) << where << " planned bundles " << h << ", " << l;
      ASSERT_TRUE(s.revoke_deadline(l).has_value())
          << where << " holder " << l << " keeps what " << h << " could get, unrevoked";
    }
  }
}

TEST(Invariants, HoldAfterEveryPlanInRandomRuns) {
  int plans = 0;
  for (unsigned seed = 1; seed <= 400; ++seed) {
    std::mt19937 rng(seed);
    Scheduler s(random_model(rng),
                SchedulerOptions{milliseconds{10}, milliseconds{500}, milliseconds{2000}, 2});
    const auto n = static_cast<unsigned>(s.model().bundles().size());
    const milliseconds window =
        std::max(s.options().revoke_wait, s.options().negotiation_round_max);
    // The longest a holder may keep what the plan gave away: the wait limit, extended by at
    // most negotiation_rounds_max rounds of at most negotiation_round_max each.
    const milliseconds bound = s.options().revoke_wait + s.options().negotiation_rounds_max *
                                                             s.options().negotiation_round_max;
    std::vector<std::optional<milliseconds>> waiting_since(n);
    for (int step = 0; step < 200; ++step) {
      const BundleId b = rng() % n;
      std::string where = name_of("seed ", seed);
      where += name_of(" step ", step);
      try {
        switch (rng() % 10) {
          case 0:
          case 1:
          case 2:
            s.request(b);
            break;
          case 3:
            s.release(b);
            break;
          case 4:
            s.set_priority(b, kPriorityLow + 50 * static_cast<int>(rng() % 7));
            break;
          case 5:
            if (s.requested(b)) s.trigger(b);
            break;
          case 6: {
            const milliseconds d{static_cast<long>(rng() % 1000)};
            s.set_deadline(b, Deadline{s.now(), d, s.now() + d + milliseconds{10 + rng() % 3000}});
            break;
          }
          case 7:
            s.yield(b);
            break;
          case 8:
            if (s.revoke_deadline(b)) {
              s.negotiate(b, Negotiation{milliseconds{rng() % 1000},
                                         milliseconds{1000 + rng() % 3000}, rng() % 2 == 0});
            }
            break;
          default:
            if (rng() % 4 == 0) {
              s.crash(s.model().bundle(b).applet);
            } else {
              s.advance_to(s.now() + milliseconds{rng() % 700});
            }
        }
      } catch (const std::invalid_argument&) {
        // Refused input (a self-conflicting request) changes nothing; checked below anyway.
      }
      check_plan(s, where);
      if (HasFatalFailure()) return;
      for (BundleId x = 0; x < n; ++x) {
        if (auto until = s.revoke_deadline(x)) {
          ASSERT_LE(*until - s.now(), window) << where << " reassignment window unbounded";
        }
      }
      check_no_lower_holder_keeps(s, waiting_since, bound, where);
      if (HasFatalFailure()) return;
      if (step % 25 == 24) {
        // After the reassignment window, everything planned is handed over. A deadline falling
        // due inside it (t_early reached, t_finish passed) changes the plan and starts new
        // reassignments: the window then counts from that plan.
        // The invariants hold at each of those events too.
        milliseconds end = s.now() + window;
        for (auto next = s.next_event(); next && *next <= end; next = s.next_event()) {
          const auto plans_before = s.plans_computed();
          s.advance_to(std::max(s.now(), *next));
          if (s.plans_computed() != plans_before) end = s.now() + window;
          check_plan(s, where + " (event)");
          check_no_lower_holder_keeps(s, waiting_since, bound, where + " (event)");
          if (HasFatalFailure()) return;
        }
        s.advance_to(end);
        for (BundleId x = 0; x < n; ++x) {
          ASSERT_EQ(s.active(x), s.plan().bundle_granted[x] != 0) << where;
        }
        check_no_lower_holder_keeps(s, waiting_since, bound, where);  // nobody waits now
      }
    }
    plans += static_cast<int>(s.plans_computed());
  }
  EXPECT_GT(plans, 30000);
}

}  // namespace
}  // namespace oscar::applets
