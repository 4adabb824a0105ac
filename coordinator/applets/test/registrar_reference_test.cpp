// Plans after services and applets were added and removed at run time equal the plans of a
// scheduler built from the final model with the same requests: random sequences of additions,
// removals, requests, releases and priority changes, checked after every step.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {
namespace {

// Built with += : GCC 12 warns falsely (-Wrestrict) on "literal" + std::to_string at -O3.
std::string name_of(const char* prefix, int i) {
  std::string s = prefix;
  s += std::to_string(i);
  return s;
}

// The live part of `m`, built afresh in id order, with the maps from the old ids to the new.
struct Fresh {
  Model model;
  std::map<ServiceId, ServiceId> service;
  std::map<BundleId, BundleId> bundle;
};

Fresh rebuild(const Model& m) {
  Fresh f;
  for (ServiceId s = 0; s < m.services().size(); ++s) {
    if (m.service(s).removed) continue;
    f.service[s] = f.model.add_service(m.service(s).name, m.service(s).exclusive_only);
  }
  for (ServiceId s = 0; s < m.services().size(); ++s) {
    if (m.service(s).removed) continue;
    for (const Dependency& d : m.service(s).dependencies) {
      f.model.add_dependency(f.service.at(s), f.service.at(d.service), d.access);
    }
  }
  for (AppletId a = 0; a < m.applets().size(); ++a) {
    const Applet& applet = m.applet(a);
    if (applet.removed) continue;
    const AppletId id = f.model.add_applet(applet.name, applet.fail_stop);
    for (ServiceId s : applet.provides) f.model.provide(id, f.service.at(s));
    for (BundleId b : applet.bundles) {
      std::vector<std::pair<ServiceId, Access>> resources;
      for (ResourceId r : m.bundle(b).resources) {
        resources.emplace_back(f.service.at(m.resource(r).service), m.resource(r).access);
      }
      f.bundle[b] = f.model.add_bundle(id, m.bundle(b).name, resources, m.bundle(b).priority);
    }
  }
  return f;
}

// What the test itself knows the scheduler was told, by names: kept apart from the scheduler,
// so that the reference does not copy what it checks.
struct Told {
  std::map<std::string, int> priority;  // "applet/bundle" -> its priority now
  std::set<std::string> requested;      // "applet/bundle"
  std::set<std::string> orphaned;       // services whose service applet was removed
};

std::string key(const Model& m, BundleId b) {
  return m.applet(m.bundle(b).applet).name + "/" + m.bundle(b).name;
}

// The reference: a scheduler built from the final model, told what is unavailable, with the
// requested bundles asked for at their priorities.
void expect_same_plan(const Scheduler& s, const Told& told, int step) {
  const Model& m = s.model();
  Fresh f = rebuild(m);
  Scheduler ref(f.model);
  for (const auto& [old_id, new_id] : f.service) {
    const bool orphaned = told.orphaned.contains(m.service(old_id).name);
    ASSERT_EQ(s.available(old_id), !orphaned) << "step " << step << ": " << m.service(old_id).name;
    if (orphaned) ref.set_available(new_id, false);
  }
  for (const auto& [old_id, new_id] : f.bundle) {
    ref.set_priority(new_id, told.priority.at(key(m, old_id)));
    if (told.requested.contains(key(m, old_id))) ref.request(new_id);
  }
  for (const auto& [old_id, new_id] : f.bundle) {
    ASSERT_EQ(s.requested(old_id), ref.requested(new_id)) << "step " << step;
    ASSERT_EQ(s.priority(old_id), ref.priority(new_id)) << "step " << step;
    ASSERT_EQ(s.plan().bundle_granted[old_id] != 0, ref.plan().bundle_granted[new_id] != 0)
        << "step " << step << ": bundle " << key(m, old_id);
  }
  for (const auto& [old_id, new_id] : f.service) {
    ASSERT_EQ(s.holder(old_id), ref.holder(new_id))
        << "step " << step << ": service " << m.service(old_id).name;
  }
}

// One random run. Priorities are unique, so the plan depends on what is requested and
// available only (not on the order of past requests); services only need (and their service
// applets only use) services older than themselves, so there are no cycles, whose members
// share one priority.
void run(std::uint32_t seed, int steps) {
  std::mt19937 rng(seed);
  auto pick = [&](std::size_t n) {
    return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
  };
  auto chance = [&](double p) { return std::bernoulli_distribution(p)(rng); };
  int next_priority = 1, next_name = 0;
  Model initial;
  initial.add_service("S0");
  Scheduler s(initial);
  Told told;
  auto live_services = [&](ServiceId below) {
    std::vector<ServiceId> out;
    for (ServiceId id = 0; id < std::min<std::size_t>(below, s.model().services().size()); ++id) {
      if (!s.model().service(id).removed) out.push_back(id);
    }
    return out;
  };
  auto live_applets = [&] {
    std::vector<AppletId> out;
    for (AppletId a = 0; a < s.model().applets().size(); ++a) {
      if (!s.model().applet(a).removed) out.push_back(a);
    }
    return out;
  };
  auto bundles_over = [&](const std::vector<ServiceId>& usable) {
    std::vector<NewBundle> out;
    const int count = 1 + static_cast<int>(pick(2));
    for (int i = 0; i < count && !usable.empty(); ++i) {
      NewBundle b{name_of("b", i), next_priority++ * 7, {}, std::nullopt};
      std::vector<ServiceId> taken;
      const int resources = 1 + static_cast<int>(pick(2));
      for (int r = 0; r < resources; ++r) {
        const ServiceId svc = usable[pick(usable.size())];
        if (std::find(taken.begin(), taken.end(), svc) != taken.end()) continue;
        taken.push_back(svc);
        const bool shared = !s.model().service(svc).exclusive_only && chance(0.4);
        b.resources.emplace_back(s.model().service(svc).name,
                                 shared ? Access::kShared : Access::kExclusive);
      }
      out.push_back(std::move(b));
    }
    return out;
  };
  for (int step = 0; step < steps; ++step) {
    const int op = static_cast<int>(pick(10));
    const auto applets = live_applets();
    if (op <= 1) {  // add services and applets
      ModelAddition add;
      const auto older = live_services(~ServiceId{0});
      const int services = static_cast<int>(pick(3));
      for (int i = 0; i < services; ++i) {
        NewService svc{name_of("S", ++next_name), chance(0.3), {}};
        if (!older.empty() && chance(0.4)) {
          const ServiceId need = older[pick(older.size())];
          const bool shared = !s.model().service(need).exclusive_only && chance(0.5);
          svc.needs.emplace_back(s.model().service(need).name,
                                 shared ? Access::kShared : Access::kExclusive);
        }
        add.services.push_back(std::move(svc));
      }
      const int count = 1 + static_cast<int>(pick(2));
      for (int i = 0; i < count && !older.empty(); ++i) {
        NewApplet a{name_of("A", ++next_name), false, {}, bundles_over(older)};
        if (i == 0 && !add.services.empty() && chance(0.5)) {
          a.provides.push_back(add.services.front().name);  // newer than all it uses
        }
        add.applets.push_back(std::move(a));
      }
      // Provide again a service whose service applet was removed, using only older services.
      for (ServiceId id : older) {
        const Service& svc = s.model().service(id);
        if (s.available(id) || svc.provider || !chance(0.5)) continue;
        const auto below = live_services(id);
        if (below.empty()) continue;
        add.applets.push_back(
            NewApplet{name_of("P", ++next_name), false, {svc.name}, bundles_over(below)});
        break;
      }
      s.add(add);
      for (const NewApplet& a : add.applets) {
        for (const NewBundle& b : a.bundles) told.priority[a.name + "/" + b.name] = b.priority;
        for (const std::string& p : a.provides) told.orphaned.erase(p);
      }
    } else if (op == 2 && !applets.empty()) {
      const AppletId victim = applets[pick(applets.size())];
      const std::string name = s.model().applet(victim).name;
      for (ServiceId p : s.model().applet(victim).provides) {
        told.orphaned.insert(s.model().service(p).name);
      }
      std::erase_if(told.requested,
                    [&](const std::string& k) { return k.rfind(name + "/", 0) == 0; });
      s.remove_applet(victim);
    } else if (op == 3 && !live_services(~ServiceId{0}).empty()) {
      const auto services = live_services(~ServiceId{0});
      const ServiceId victim = services[pick(services.size())];
      const auto before = s.model().services().size();
      try {
        s.remove_service(victim);
        EXPECT_TRUE(s.model().service(victim).removed);
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("cannot be removed while"), std::string::npos);
        EXPECT_FALSE(s.model().service(victim).removed);
      }
      EXPECT_EQ(s.model().services().size(), before);
    } else if (!applets.empty()) {
      const auto& mine = s.model().applet(applets[pick(applets.size())]).bundles;
      if (mine.empty()) continue;
      const BundleId b = mine[pick(mine.size())];
      if (op <= 7) {
        try {
          s.request(b);
          told.requested.insert(key(s.model(), b));
        } catch (const std::invalid_argument&) {
          // two requested bundles of one applet on one exclusive service: refused, as it should
        }
      } else if (op == 8) {
        s.release(b);
        told.requested.erase(key(s.model(), b));
      } else {
        told.priority[key(s.model(), b)] = next_priority * 7;
        s.set_priority(b, next_priority++ * 7);
      }
    }
    expect_same_plan(s, told, step);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

TEST(RegistrarReference, RandomAdditionsAndRemovalsGiveTheFinalModelsPlan) {
  for (std::uint32_t seed = 1; seed <= 60; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    run(seed, 80);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

}  // namespace
}  // namespace oscar::applets
