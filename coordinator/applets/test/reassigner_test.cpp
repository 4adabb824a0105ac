// The per-service reassigners of the Scheduler (seed 000 §4.4.1, Abb. 4.13–4.14).
#include <gtest/gtest.h>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {
namespace {

using std::chrono::milliseconds;
constexpr auto kX = Access::kExclusive;
constexpr auto kS = Access::kShared;

std::vector<Notification> of_kind(const std::vector<Notification>& all, Notification::Kind kind) {
  std::vector<Notification> out;
  for (const Notification& n : all) {
    if (n.kind == kind) out.push_back(n);
  }
  return out;
}

// Holder A uses X and Y in one bundle; B wants X, C wants Y, both with a higher priority.
struct SplitHolder {
  Model m;
  ServiceId x = m.add_service("X");
  ServiceId y = m.add_service("Y");
  AppletId a = m.add_applet("A");
  BundleId held = m.add_bundle(a, "xy", {{x, kX}, {y, kX}});
  BundleId bx = m.add_bundle(m.add_applet("B"), "x", {{x, kX}}, kPriorityHigh);
  BundleId cy = m.add_bundle(m.add_applet("C"), "y", {{y, kX}}, kPriorityHigh);
  AppletId b() const { return m.bundle(bx).applet; }
  AppletId c() const { return m.bundle(cy).applet; }
};

TEST(Reassigner, EachServiceOfARevokedBundleTellsItsOwnNewHolder) {
  SplitHolder t;
  Scheduler s(t.m);
  s.request(t.held);
  s.take_notifications();
  s.request(t.bx);
  auto told = of_kind(s.take_notifications(), Notification::Kind::kRevokeRequested);
  ASSERT_EQ(told.size(), 2u);  // one reassigner per service of the bundle
  for (const Notification& n : told) {
    ASSERT_TRUE(n.service.has_value());
    EXPECT_EQ(n.bundle, t.held);
    EXPECT_EQ(n.until, milliseconds{5000});
    if (*n.service == t.x) {
      EXPECT_EQ(n.new_holders, std::vector<AppletId>{t.b()});
    } else {
      EXPECT_EQ(*n.service, t.y);
      EXPECT_TRUE(n.new_holders.empty());  // Y goes to nobody (the bundle is all or nothing)
    }
  }
  s.advance_to(milliseconds{1000});
  s.request(t.cy);  // Y's reassigner now gives Y to C: A hears it, the wait limit stands
  told = of_kind(s.take_notifications(), Notification::Kind::kRevokeRequested);
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0].service, t.y);
  EXPECT_EQ(told[0].new_holders, std::vector<AppletId>{t.c()});
  EXPECT_EQ(told[0].until, milliseconds{5000});
  EXPECT_EQ(s.reassignment(t.x).to, std::vector<AppletId>{t.b()});
  EXPECT_EQ(s.reassignment(t.y).to, std::vector<AppletId>{t.c()});
  s.yield(t.held);  // the whole bundle goes back: both reassigners end and both grant
  EXPECT_TRUE(s.reassignment(t.x).giving.empty());
  EXPECT_TRUE(s.reassignment(t.y).giving.empty());
  EXPECT_TRUE(s.active(t.bx));
  EXPECT_TRUE(s.active(t.cy));
}

// C's deadline bounds what Y's reassigner may give; X's reassigner answers on its own.
TEST(Reassigner, EachReassignerDecidesTheNegotiationForItsService) {
  SplitHolder t;
  Scheduler s(t.m);
  s.request(t.held);
  s.request(t.bx);
  s.request(t.cy);
  // Latest start 2000 ms; t_finish after the forced revocation at 5000 ms (it expires then).
  s.set_deadline(t.cy, Deadline{milliseconds{0}, milliseconds{4000}, milliseconds{6000}});
  s.take_notifications();
  const Notification summary =
      s.negotiate(t.held, Negotiation{milliseconds{2500}, milliseconds{8000}, true});
  EXPECT_EQ(summary.kind, Notification::Kind::kNegotiationRejected);
  EXPECT_EQ(summary.until, milliseconds{5000});
  const auto notes = s.take_notifications();
  const auto accepted = of_kind(notes, Notification::Kind::kNegotiationAccepted);
  const auto rejected = of_kind(notes, Notification::Kind::kNegotiationRejected);
  ASSERT_EQ(accepted.size(), 1u);
  ASSERT_EQ(rejected.size(), 1u);
  EXPECT_EQ(accepted[0].service, t.x);
  EXPECT_EQ(accepted[0].until, milliseconds{8000});
  EXPECT_EQ(rejected[0].service, t.y);  // 2500 ms would pass C's latest start (2000 ms)
  EXPECT_EQ(s.reassignment(t.x).giving.at(0).until, milliseconds{8000});
  EXPECT_EQ(s.revoke_deadline(t.held), milliseconds{5000});
  s.advance_to(milliseconds{4999});
  EXPECT_TRUE(s.active(t.held));
  s.advance_to(milliseconds{5000});  // Y's wait limit: force takes the whole bundle
  const auto forced = of_kind(s.take_notifications(), Notification::Kind::kRevokedByForce);
  ASSERT_EQ(forced.size(), 1u);
  EXPECT_EQ(forced[0].service, t.y);
  EXPECT_FALSE(s.active(t.held));
  EXPECT_TRUE(s.reassignment(t.x).giving.empty());
  EXPECT_TRUE(s.active(t.bx));
  EXPECT_TRUE(s.active(t.cy));
}

// A new shared user of X does not wait for a shared user of X being revoked for another
// service: X's reassigner has nobody to take X from that clashes with it.
TEST(Reassigner, SharedNewcomerDoesNotWaitForASharedHolderBeingRevoked) {
  Model m;
  const ServiceId x = m.add_service("X");
  const ServiceId z = m.add_service("Z");
  const BundleId held = m.add_bundle(m.add_applet("A"), "xz", {{x, kS}, {z, kX}});
  const BundleId bz = m.add_bundle(m.add_applet("B"), "z", {{z, kX}}, kPriorityHigh);
  const BundleId dx = m.add_bundle(m.add_applet("D"), "x", {{x, kS}});
  Scheduler s(m);
  s.request(held);
  s.request(bz);
  s.request(dx);
  EXPECT_TRUE(s.revoke_deadline(held).has_value());
  EXPECT_TRUE(s.active(dx));   // beside A's shared use
  EXPECT_FALSE(s.active(bz));  // Z is still A's
  EXPECT_EQ(s.active_holder(x), "A,D");
  s.yield(held);
  EXPECT_TRUE(s.active(bz));
}

// Second degree (Abb. 4.8): the docking controller's holder gives back Dock and, down the
// hierarchy, the Pilot it drives; each reassigner names its own new holder.
TEST(Reassigner, DependencyDownTheHierarchyHasItsOwnReassigner) {
  Model m;
  const ServiceId pilot = m.add_service("Pilot");
  const ServiceId dock = m.add_service("DockingController");
  m.add_dependency(dock, pilot);
  const BundleId charge = m.add_bundle(m.add_applet("Battery"), "dock", {{dock, kX}});
  const BundleId drive = m.add_bundle(m.add_applet("DriveTo"), "p", {{pilot, kX}}, kPriorityHigh);
  Scheduler s(m);
  s.request(charge);
  s.take_notifications();
  s.request(drive);
  const auto told = of_kind(s.take_notifications(), Notification::Kind::kRevokeRequested);
  ASSERT_EQ(told.size(), 2u);
  for (const Notification& n : told) {
    const auto expected = *n.service == pilot ? std::vector<AppletId>{m.bundle(drive).applet}
                                              : std::vector<AppletId>{};
    EXPECT_EQ(n.new_holders, expected) << m.service(*n.service).name;
  }
}

// The UI service applet holds the monitor itself: a UI user being revoked hears from the UI's
// reassigner only, while the monitor's reassigner tracks it silently until it yields (the UI it
// uses needs the monitor until then).
TEST(Reassigner, UserOfAServiceAppletHearsOnlyAboutWhatItUsesItself) {
  Model m;
  const ServiceId ui = m.add_service("UI", true);
  const ServiceId monitor = m.add_service("Monitor");
  const AppletId provider = m.add_applet("UIService");
  m.provide(provider, ui);
  m.add_bundle(provider, "io", {{monitor, kX}});
  const BundleId menu = m.add_bundle(m.add_applet("Menu"), "ui", {{ui, kX}});
  const BundleId drive = m.add_bundle(m.add_applet("DriveTo"), "ui", {{ui, kX}}, kPriorityHigh);
  Scheduler s(m);
  s.request(menu);
  s.take_notifications();
  s.request(drive);
  const auto told = of_kind(s.take_notifications(), Notification::Kind::kRevokeRequested);
  ASSERT_EQ(told.size(), 1u);
  EXPECT_EQ(told[0].service, ui);
  ASSERT_EQ(s.reassignment(monitor).giving.size(), 1u);
  EXPECT_EQ(s.reassignment(monitor).giving[0].bundle, menu);
  s.negotiate(menu, Negotiation{milliseconds{100}, milliseconds{100}, true});
  const auto replies = of_kind(s.take_notifications(), Notification::Kind::kNegotiationAccepted);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].service, ui);
  s.yield(menu);
  EXPECT_TRUE(s.reassignment(monitor).giving.empty());
  EXPECT_TRUE(s.active(drive));
}

}  // namespace
}  // namespace oscar::applets
