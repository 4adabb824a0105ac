// One test per planning rule of seed 000 §4.2–4.5 (Abb. 4.6, 4.8, 4.9, 4.15/4.16, 4.18, 4.19).
#include "oscar/applets/plan.hpp"

#include <gtest/gtest.h>

#include <functional>

#include "oscar/applets/scheduler.hpp"
#include "test_support.hpp"

namespace oscar::applets {
namespace {

constexpr auto kX = Access::kExclusive;
constexpr auto kS = Access::kShared;

TEST(Plan, HigherPriorityWinsAFirstDegreeConflict) {  // Abb. 4.8 top
  Model m;
  const ServiceId pilot = m.add_service("Pilot");
  const BundleId drive = m.add_bundle(m.add_applet("DriveTo"), "p", {{pilot, kX}}, kPriorityNormal);
  const BundleId bat = m.add_bundle(m.add_applet("Battery"), "p", {{pilot, kX}}, kPriorityHigh);
  Scheduler s(m);
  s.request(drive);
  EXPECT_EQ(s.holder(pilot), "DriveTo");
  s.request(bat);
  EXPECT_EQ(s.holder(pilot), "Battery");
  EXPECT_FALSE(s.plan().bundle_granted[drive]);
}

TEST(Plan, SecondDegreeConflictThroughAConfiguredDependency) {  // Abb. 4.8 bottom
  Model m;
  const ServiceId pilot = m.add_service("Pilot");
  const ServiceId dock = m.add_service("Dock");
  m.add_dependency(dock, pilot);
  const BundleId drive = m.add_bundle(m.add_applet("DriveTo"), "p", {{pilot, kX}}, kPriorityNormal);
  const BundleId bat = m.add_bundle(m.add_applet("Battery"), "d", {{dock, kX}}, kPriorityHigh);
  Scheduler s(m);
  s.request(drive);
  EXPECT_EQ(s.holder(dock), "blocked");  // nobody asked, but its dependency is taken
  s.request(bat);
  EXPECT_EQ(s.holder(dock), "Battery");
  EXPECT_EQ(s.holder(pilot), "blocked");  // held up by the docking controller
  EXPECT_FALSE(s.plan().bundle_granted[drive]);
  s.release(bat);
  EXPECT_EQ(s.holder(pilot), "DriveTo");
}

TEST(Plan, SharedUsersCoexistAndExcludeAnExclusiveOne) {
  Model m;
  const ServiceId svc = m.add_service("Counter");
  const BundleId a = m.add_bundle(m.add_applet("A"), "c", {{svc, kS}});
  const BundleId b = m.add_bundle(m.add_applet("B"), "c", {{svc, kS}});
  const BundleId x = m.add_bundle(m.add_applet("X"), "c", {{svc, kX}});
  Scheduler s(m);
  s.request(a);
  s.request(b);
  s.request(x);
  EXPECT_EQ(s.holder(svc), "A,B");
  EXPECT_FALSE(s.plan().bundle_granted[x]);
  s.set_priority(x, kPriorityHigh);
  EXPECT_EQ(s.holder(svc), "X");
}

TEST(Plan, BundleIsGrantedAllOrNothing) {  // Abb. 4.6
  Model m;
  const ServiceId ui = m.add_service("UI", true);
  const ServiceId pilot = m.add_service("Pilot");
  const BundleId menu = m.add_bundle(m.add_applet("Menu"), "ui", {{ui, kX}}, kPriorityHigh);
  const BundleId drive = m.add_bundle(m.add_applet("DriveTo"), "task", {{ui, kX}, {pilot, kX}});
  Scheduler s(m);
  s.request(menu);
  s.request(drive);
  EXPECT_FALSE(s.plan().bundle_granted[drive]);
  EXPECT_EQ(s.holder(pilot), "blocked");  // free, but its bundle cannot have the UI
  EXPECT_TRUE(s.plan().uses[pilot].empty());
  s.release(menu);
  EXPECT_EQ(s.holder(pilot), "DriveTo");
  EXPECT_EQ(s.holder(ui), "DriveTo");
}

// Abb. 4.15/4.16: App1 (high) needs S1 from a low-priority service applet that needs S2, which a
// middle-priority App2 wants. Inheritance gives S2 to the service applet.
TEST(Plan, InheritancePreventsPriorityInversion) {
  Model m;
  const ServiceId s1 = m.add_service("S1");
  const ServiceId s2 = m.add_service("S2");
  const AppletId sa = m.add_applet("ServiceApplet");
  m.provide(sa, s1);
  const BundleId sa_b = m.add_bundle(sa, "s2", {{s2, kX}}, kPriorityLow);
  const BundleId app2 = m.add_bundle(m.add_applet("App2"), "s2", {{s2, kX}}, kPriorityNormal);
  const BundleId app1 = m.add_bundle(m.add_applet("App1"), "s1", {{s1, kX}}, kPriorityHigh);
  Scheduler s(m);
  s.request(sa_b);
  s.request(app2);
  EXPECT_EQ(s.holder(s2), "App2");
  EXPECT_EQ(s.holder(s1), "blocked");
  s.request(app1);
  EXPECT_EQ(s.holder(s1), "App1");
  EXPECT_EQ(s.holder(s2), "ServiceApplet");
  EXPECT_TRUE(s.plan().bundle_granted[sa_b]);
  EXPECT_FALSE(s.plan().bundle_granted[app2]);
}

// Abb. 4.9: a cycle is granted all or nothing, sorted with its highest priority.
TEST(Plan, CycleIsGrantedAllOrNothingWithItsHighestPriority) {
  testing::TwoServiceApplets t;
  Model& m = t.m;
  const ServiceId s1 = t.s1, s2 = t.s2;
  const AppletId a = t.a, b = t.b;
  const ServiceId disp = m.add_service("Display");
  const BundleId ab = m.add_bundle(a, "x", {{s2, kS}, {disp, kX}}, kPriorityLow);
  const BundleId bb = m.add_bundle(b, "x", {{s1, kS}}, kPriorityHigh);
  const BundleId other = m.add_bundle(m.add_applet("Other"), "d", {{disp, kX}}, kPriorityNormal);
  Scheduler s(m);
  s.request(other);
  s.request(ab);
  EXPECT_EQ(s.plan().effective_priority[ab], kPriorityLow);  // B has not asked yet
  s.request(bb);
  // A's bundle is sorted with B's high priority, so A takes the display from Other.
  EXPECT_EQ(s.plan().effective_priority[ab], kPriorityHigh);
  EXPECT_TRUE(s.plan().bundle_granted[ab]);
  EXPECT_TRUE(s.plan().bundle_granted[bb]);
  EXPECT_EQ(s.holder(disp), "A");
}

TEST(Plan, CycleThatCannotBeCompletedGrantsNothing) {
  testing::TwoServiceApplets t;
  Model& m = t.m;
  const ServiceId s1 = t.s1, s2 = t.s2;
  const AppletId a = t.a, b = t.b;
  const BundleId ab = m.add_bundle(a, "x", {{s2, kS}});
  const BundleId bb = m.add_bundle(b, "x", {{s1, kS}});
  const BundleId x = m.add_bundle(m.add_applet("X"), "s1", {{s1, kX}}, kPrioritySystem);
  Scheduler s(m);
  s.request(ab);
  s.request(bb);
  EXPECT_TRUE(s.plan().bundle_granted[ab] && s.plan().bundle_granted[bb]);
  s.request(x);
  // X's exclusive use of S1 needs A's resources, which need S2, which needs B's shared use of
  // S1: X cannot have S1 alone, so X is refused and the cycle stays whole.
  EXPECT_FALSE(s.plan().bundle_granted[x]);
  EXPECT_TRUE(s.plan().bundle_granted[ab] && s.plan().bundle_granted[bb]);
}

// Abb. 4.18: without triggering App2 keeps Service 2; App3's trigger moves it to the front of
// its level; after the priority is restored nothing oscillates back.
TEST(Plan, TriggeringSwitchesOnceWithoutOscillation) {
  Model m;
  const ServiceId s1 = m.add_service("Service1");
  const ServiceId s2 = m.add_service("Service2");
  const AppletId app2 = m.add_applet("App2");
  const BundleId a1 = m.add_bundle(m.add_applet("App1"), "s1", {{s1, kX}}, kPriorityHigh);
  const BundleId a2s1 = m.add_bundle(app2, "s1", {{s1, kX}}, kPriorityHigh);
  const BundleId a2s2 = m.add_bundle(app2, "s2", {{s2, kX}}, kPriorityNormal);
  const BundleId a3 = m.add_bundle(m.add_applet("App3"), "s2", {{s2, kX}}, kPriorityNormal);
  Scheduler s(m);
  for (BundleId b : {a1, a2s1, a2s2, a3}) s.request(b);
  EXPECT_EQ(s.holder(s1), "App1");
  EXPECT_EQ(s.holder(s2), "App2");
  s.trigger(a3);
  EXPECT_EQ(s.holder(s2), "App3");
  EXPECT_EQ(s.priority(a3), kPriorityNormal);  // restored
  const auto plans = s.plans_computed();
  s.set_priority(a1, kPriorityHigh);  // any recomputation keeps the switch
  EXPECT_EQ(s.plans_computed(), plans + 1);
  EXPECT_EQ(s.holder(s2), "App3");
  EXPECT_FALSE(s.plan().bundle_granted[a2s2]);
}

// Seed §4.5.2: priorities are levels with room in between; 250 lies between normal and high.
TEST(Plan, IntermediatePriorityLevelsSortBetweenTheNamedOnes) {
  Model m;
  const ServiceId svc = m.add_service("S");
  const BundleId normal = m.add_bundle(m.add_applet("Normal"), "s", {{svc, kX}}, kPriorityNormal);
  const BundleId between = m.add_bundle(m.add_applet("Between"), "s", {{svc, kX}}, 250);
  const BundleId high = m.add_bundle(m.add_applet("High"), "s", {{svc, kX}}, kPriorityHigh);
  Scheduler s(m);
  s.request(normal);
  s.request(between);
  EXPECT_EQ(s.holder(svc), "Between");
  s.request(high);
  EXPECT_EQ(s.holder(svc), "High");
  s.set_priority(between, kPriorityHigh + 1);
  EXPECT_EQ(s.holder(svc), "Between");
}

// Abb. 4.19: every request, release, priority and deadline change computes a new plan.
TEST(Plan, IsRecomputedOnEveryRequestReleasePriorityAndDeadlineChange) {
  Model m;
  const ServiceId svc = m.add_service("S");
  const BundleId a = m.add_bundle(m.add_applet("A"), "s", {{svc, kX}});
  const BundleId b = m.add_bundle(m.add_applet("B"), "s", {{svc, kX}});
  Scheduler s(m);
  using std::chrono::milliseconds;
  const std::vector<std::function<void()>> changes = {
      [&] { s.request(a); }, [&] { s.request(b); }, [&] { s.set_priority(b, kPriorityHigh); },
      [&] {
        s.set_deadline(a, Deadline{milliseconds{0}, milliseconds{10}, milliseconds{100}});
      },
      [&] { s.release(b); }};
  for (std::size_t i = 0; i < changes.size(); ++i) {
    const auto before = s.plans_computed();
    changes[i]();
    EXPECT_EQ(s.plans_computed(), before + 1) << "change " << i;
  }
  EXPECT_EQ(s.holder(svc), "A");
}

TEST(Plan, HeldBundleKeepsItsPlaceAgainstANewEqualRequest) {
  Model m;
  const ServiceId svc = m.add_service("S");
  const BundleId late = m.add_bundle(m.add_applet("Late"), "s", {{svc, kX}});
  const BundleId early = m.add_bundle(m.add_applet("Early"), "s", {{svc, kX}});
  Scheduler s(m);
  s.request(early);
  s.request(late);
  EXPECT_EQ(s.holder(svc), "Early");  // bundle id order would favour Late; W order wins
}

TEST(Plan, EarliestRelativeDeadlineFirstWithinOnePriority) {
  Model m;
  const ServiceId svc = m.add_service("S");
  const BundleId a = m.add_bundle(m.add_applet("A"), "s", {{svc, kX}});
  const BundleId b = m.add_bundle(m.add_applet("B"), "s", {{svc, kX}});
  const BundleId c = m.add_bundle(m.add_applet("C"), "s", {{svc, kX}}, kPriorityHigh);
  Scheduler s(m);
  using std::chrono::milliseconds;
  s.request(a);
  s.set_deadline(a, Deadline{milliseconds{0}, milliseconds{100}, milliseconds{5000}});
  s.request(b);
  s.set_deadline(b, Deadline{milliseconds{0}, milliseconds{100}, milliseconds{1000}});
  EXPECT_EQ(s.holder(svc), "B");  // relative deadline 900 ms before 4900 ms
  s.request(c);                   // a higher priority beats any deadline
  EXPECT_EQ(s.holder(svc), "C");
}

TEST(Plan, OverlappingDeadlinesAreReportedToBothApplets) {  // eq. 4.11
  Model m;
  const ServiceId svc = m.add_service("S");
  const BundleId a = m.add_bundle(m.add_applet("A"), "s", {{svc, kX}});
  const BundleId b = m.add_bundle(m.add_applet("B"), "s", {{svc, kX}});
  Scheduler s(m);
  using std::chrono::milliseconds;
  s.request(a);
  s.request(b);
  s.set_deadline(a, Deadline{milliseconds{0}, milliseconds{600}, milliseconds{1000}});
  s.take_notifications();
  s.set_deadline(b, Deadline{milliseconds{0}, milliseconds{500}, milliseconds{1000}});
  ASSERT_EQ(s.plan().deadline_overlaps.size(), 1u);
  int reported = 0;
  for (const Notification& n : s.take_notifications()) {
    if (n.kind != Notification::Kind::kDeadlineOverlap) continue;
    ++reported;
    EXPECT_EQ(*n.other, n.bundle == a ? b : a);
  }
  EXPECT_EQ(reported, 2);
  // 0 + 600 + 300 <= 1000: no overlap any more.
  s.set_deadline(b, Deadline{milliseconds{0}, milliseconds{300}, milliseconds{1000}});
  EXPECT_TRUE(s.plan().deadline_overlaps.empty());
}

TEST(Plan, DeadlinesOverlapCountsTheContextSwitch) {
  using std::chrono::milliseconds;
  const Deadline a{milliseconds{0}, milliseconds{400}, milliseconds{1000}};
  const Deadline b{milliseconds{0}, milliseconds{500}, milliseconds{1000}};
  EXPECT_FALSE(deadlines_overlap(a, b, milliseconds{100}));
  EXPECT_TRUE(deadlines_overlap(a, b, milliseconds{101}));
}

}  // namespace
}  // namespace oscar::applets
