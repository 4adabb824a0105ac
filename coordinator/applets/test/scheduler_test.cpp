#include "oscar/applets/scheduler.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_support.hpp"

namespace oscar::applets {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;
constexpr auto kX = Access::kExclusive;

using testing::error_of;

struct TwoApplets {
  Model m;
  ServiceId svc = m.add_service("S");
  BundleId low = m.add_bundle(m.add_applet("Low"), "s", {{svc, kX}}, kPriorityNormal);
  BundleId high = m.add_bundle(m.add_applet("High"), "s", {{svc, kX}}, kPriorityHigh);
};

TEST(Scheduler, InvalidDeadlinesNameTheInequality) {
  TwoApplets t;
  Scheduler s(t.m, SchedulerOptions{milliseconds{50}});
  EXPECT_THAT(
      error_of([&] {
        s.set_deadline(t.low, Deadline{milliseconds{0}, milliseconds{960}, milliseconds{1000}});
      }),
      HasSubstr("(eq. 4.9)"));
  s.advance_to(milliseconds{500});
  EXPECT_THAT(
      error_of([&] {
        s.set_deadline(t.low, Deadline{milliseconds{0}, milliseconds{460}, milliseconds{1000}});
      }),
      HasSubstr("now + t_duration + c <= t_finish (eq. 4.10)"));
  EXPECT_THAT(error_of([&] { s.advance_to(milliseconds{100}); }), HasSubstr("time only advances"));
  EXPECT_THAT(
      error_of([&] {
        s.set_deadline(t.low, Deadline{milliseconds{600}, milliseconds{-1}, milliseconds{2000}});
      }),
      HasSubstr("bundle 's': deadline t_duration -1 ms is negative"));
}

// A bundle configured with `deadline:` is a reservation for later at every request: early 5 s
// means 5 s after that request, and the request expires at finish.
TEST(Scheduler, AConfiguredDeadlineCountsFromEachRequest) {
  TwoApplets t;
  t.m.set_request_deadline(t.low,
                           Deadline{milliseconds{5000}, milliseconds{1000}, milliseconds{6500}});
  Scheduler s(t.m);
  s.advance_to(milliseconds{1000});
  s.request(t.low);
  EXPECT_FALSE(s.active(t.low)) << "granted before early";
  s.advance_to(milliseconds{5999});
  EXPECT_FALSE(s.active(t.low));
  s.advance_to(milliseconds{6000});
  EXPECT_TRUE(s.active(t.low));
  s.take_notifications();
  s.advance_to(milliseconds{7501});  // finish passed: the request is withdrawn
  EXPECT_FALSE(s.requested(t.low));
  bool expired = false;
  for (const auto& n : s.take_notifications()) {
    expired = expired || (n.kind == Notification::Kind::kDeadlineExpired && n.bundle == t.low);
  }
  EXPECT_TRUE(expired);
  s.advance_to(milliseconds{8000});
  s.request(t.low);  // counted from this request
  s.advance_to(milliseconds{12999});
  EXPECT_FALSE(s.active(t.low));
  s.advance_to(milliseconds{13000});
  EXPECT_TRUE(s.active(t.low));
}

TEST(Scheduler, AConfiguredDeadlineMustFitItsWindow) {
  TwoApplets t;
  EXPECT_THAT(error_of([&] {
                t.m.set_request_deadline(
                    t.low, Deadline{milliseconds{500}, milliseconds{600}, milliseconds{1000}});
              }),
              HasSubstr("applet 'Low' bundle 's': deadline needs early + duration <= finish "
                        "(eq. 4.9), but 500 ms + 600 ms > 1000 ms"));
  EXPECT_THAT(error_of([&] {
                t.m.set_request_deadline(
                    t.low, Deadline{milliseconds{-1}, milliseconds{0}, milliseconds{1000}});
              }),
              HasSubstr("counted from the request and cannot be negative"));
}

TEST(Scheduler, SameExclusiveServiceInTwoRequestedBundlesOfOneAppletIsRejected) {
  Model m;
  const ServiceId ui = m.add_service("UI", true);
  const ServiceId pilot = m.add_service("Pilot");
  const AppletId a = m.add_applet("Battery");
  const BundleId b1 = m.add_bundle(a, "warn", {{ui, kX}});
  const BundleId b2 = m.add_bundle(a, "dock", {{ui, kX}, {pilot, kX}});
  Scheduler s(m);
  s.request(b1);
  EXPECT_THAT(error_of([&] { s.request(b2); }),
              HasSubstr("bundle 'dock' with service 'UI' which its requested bundle 'warn'"));
  s.release(b1);
  s.request(b2);
  EXPECT_TRUE(s.requested(b2));
}

// The coordinator publishes it with every plan (AppletPlan.plan_us).
TEST(Scheduler, KnowsHowLongItsLastPlanTookAndHowManyItMade) {
  TwoApplets t;
  Scheduler s(t.m);  // plans once: nothing requested
  EXPECT_EQ(s.plans_computed(), 1u);
  s.request(t.low);
  EXPECT_EQ(s.plans_computed(), 2u);
  EXPECT_GT(s.last_plan_time().count(), 0);
}

TEST(Scheduler, TriggerOfAnUnrequestedBundleIsRejected) {
  TwoApplets t;
  Scheduler s(t.m);
  EXPECT_THAT(error_of([&] { s.trigger(t.low); }), HasSubstr("request it first"));
}

TEST(Scheduler, RevocationWaitsForYieldThenHandsOver) {
  TwoApplets t;
  Scheduler s(t.m);
  s.request(t.low);
  EXPECT_TRUE(s.active(t.low));
  s.take_notifications();
  s.request(t.high);
  EXPECT_TRUE(s.plan().bundle_granted[t.high]);
  EXPECT_FALSE(s.active(t.high));  // Low still uses it
  auto notes = s.take_notifications();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].kind, Notification::Kind::kRevokeRequested);
  EXPECT_EQ(notes[0].new_holders, std::vector<AppletId>{t.m.bundle(t.high).applet});
  s.yield(t.low);
  EXPECT_TRUE(s.active(t.high));
  EXPECT_FALSE(s.active(t.low));
  s.release(t.high);
  EXPECT_TRUE(s.active(t.low));  // still requested: granted again
}

TEST(Scheduler, RevokesByForceAfterTheWaitLimit) {
  TwoApplets t;
  Scheduler s(t.m, SchedulerOptions{milliseconds{0}, milliseconds{5000}});
  s.request(t.low);
  s.request(t.high);
  s.advance_to(milliseconds{4999});
  EXPECT_TRUE(s.active(t.low));
  s.take_notifications();
  s.advance_to(milliseconds{5000});
  EXPECT_FALSE(s.active(t.low));
  EXPECT_TRUE(s.active(t.high));
  auto notes = s.take_notifications();
  ASSERT_GE(notes.size(), 2u);
  EXPECT_EQ(notes[0].kind, Notification::Kind::kRevokedByForce);
  EXPECT_EQ(notes[1].kind, Notification::Kind::kGranted);
}

TEST(Scheduler, NegotiationExtendsTheWaitWithinTheRoundLimit) {
  TwoApplets t;
  SchedulerOptions o;
  o.revoke_wait = milliseconds{1000};
  o.negotiation_round_max = milliseconds{20000};
  o.negotiation_rounds_max = 2;
  Scheduler s(t.m, o);
  s.request(t.low);
  s.request(t.high);
  auto n = s.negotiate(t.low, Negotiation{milliseconds{3000}, milliseconds{8000}, true});
  EXPECT_EQ(n.kind, Notification::Kind::kNegotiationAccepted);
  EXPECT_EQ(n.until, milliseconds{8000});
  // An objection insisting on more than a round may grant is rejected (the wait stands).
  n = s.negotiate(t.low, Negotiation{milliseconds{0}, milliseconds{30000}, false});
  EXPECT_EQ(n.kind, Notification::Kind::kNegotiationRejected);
  EXPECT_EQ(n.until, milliseconds{8000});
  n = s.negotiate(t.low, Negotiation{milliseconds{100}, milliseconds{100}, true});
  EXPECT_EQ(n.kind, Notification::Kind::kNegotiationRejected);  // third round > 2
  s.advance_to(milliseconds{7999});
  EXPECT_TRUE(s.active(t.low));
  s.advance_to(milliseconds{8000});
  EXPECT_TRUE(s.active(t.high));
}

TEST(Scheduler, NegotiationCannotPassTheRoundLimitOrANewHoldersDeadline) {
  TwoApplets t;
  Scheduler s(t.m);
  s.request(t.low);
  s.request(t.high);
  s.set_deadline(t.high, Deadline{milliseconds{0}, milliseconds{1000}, milliseconds{3000}});
  auto n = s.negotiate(t.low, Negotiation{milliseconds{1500}, milliseconds{25000}, true});
  EXPECT_EQ(n.kind, Notification::Kind::kNegotiationAccepted);
  EXPECT_EQ(n.until, milliseconds{5000});  // min 1500 fits the deadline; the wait is longer
  n = s.negotiate(t.low, Negotiation{milliseconds{2500}, milliseconds{2500}, true});
  EXPECT_EQ(n.kind, Notification::Kind::kNegotiationRejected);  // latest start is 2000 ms
}

// Seed §4.5.3: a round carries a vote, agreeing to the revocation or objecting to it, and the
// scheduler agrees to or rejects that round; an objection is negotiable like an agreement (it used
// to be rejected whatever it asked for).
TEST(Scheduler, ObjectionIsUpheldWhenTheTimeItInsistsOnFits) {
  TwoApplets t;
  SchedulerOptions o;
  o.revoke_wait = milliseconds{1000};
  Scheduler s(t.m, o);
  s.request(t.low);
  s.request(t.high);
  auto n = s.negotiate(t.low, Negotiation{milliseconds{2000}, milliseconds{4000}, false});
  EXPECT_EQ(n.kind, Notification::Kind::kNegotiationAccepted);
  EXPECT_EQ(n.until, milliseconds{4000});
  s.advance_to(milliseconds{3999});
  EXPECT_TRUE(s.active(t.low));
  EXPECT_FALSE(s.active(t.high));
  s.advance_to(milliseconds{4000});
  EXPECT_TRUE(s.active(t.high));
}

// What the vote says decides the outcome: with a new holder's latest start at 2000 ms only the
// minimum fits, which an agreement accepts as a compromise and an objection does not offer.
TEST(Scheduler, ObjectionAndAgreementAskingTheSameTimesDifferWhenOnlyTheMinimumFits) {
  for (const bool accept : {true, false}) {
    TwoApplets t;
    Scheduler s(t.m);
    s.request(t.low);
    s.request(t.high);
    s.set_deadline(t.high, Deadline{milliseconds{0}, milliseconds{1000}, milliseconds{3000}});
    const auto n = s.negotiate(t.low, Negotiation{milliseconds{1500}, milliseconds{6000}, accept});
    EXPECT_EQ(n.kind, accept ? Notification::Kind::kNegotiationAccepted
                             : Notification::Kind::kNegotiationRejected)
        << "accept " << accept;
    EXPECT_EQ(n.until, milliseconds{5000}) << "accept " << accept;  // the wait limit stands
  }
}

// Seed §4.5.1: a deadline (t_early, t_duration, t_finish) asks for access from t_early on. A
// reservation for 5000-6000 ms made at 0 ms took the service at once; now it takes nothing
// before 5000 ms, and the plan at 5000 ms grants it (EDF puts it before a request without one).
TEST(Scheduler, ReservationForALaterTimeIsGrantedFromItsEarliestStartOn) {
  Model m;
  const ServiceId svc = m.add_service("S");
  const BundleId later = m.add_bundle(m.add_applet("Later"), "s", {{svc, kX}});
  const BundleId now = m.add_bundle(m.add_applet("Now"), "s", {{svc, kX}});
  Scheduler s(m);
  s.set_deadline(later, Deadline{milliseconds{5000}, milliseconds{1000}, milliseconds{6000}});
  s.request(later);
  EXPECT_FALSE(s.plan().bundle_granted[later]);
  EXPECT_FALSE(s.active(later));
  EXPECT_EQ(s.holder(svc), "undef");  // nobody asks for it yet
  s.request(now);
  EXPECT_TRUE(s.active(now));  // the reservation takes nothing from others before its time
  EXPECT_EQ(s.next_event(), milliseconds{5000});
  s.advance_to(milliseconds{4999});
  EXPECT_FALSE(s.plan().bundle_granted[later]);
  const auto plans = s.plans_computed();
  s.advance_to(milliseconds{5000});
  EXPECT_EQ(s.plans_computed(), plans + 1);  // a new plan at t_early
  EXPECT_TRUE(s.plan().bundle_granted[later]);
  EXPECT_EQ(s.revoke_deadline(now), milliseconds{10000});  // given back from 5000 ms on
  s.yield(now);
  EXPECT_TRUE(s.active(later));
}

// Seed §4.5.1: t_finish is the latest end of the access. When it passes, the request is withdrawn
// and the applet told (kDeadlineExpired): a waiting request is dropped, a bundle in use is given
// back through its reassigners like any other.
TEST(Scheduler, RequestExpiresWhenItsFinishPasses) {
  Model m;
  const ServiceId a = m.add_service("A");
  const ServiceId b = m.add_service("B");
  const BundleId holder = m.add_bundle(m.add_applet("Holder"), "a", {{a, kX}}, kPriorityHigh);
  const BundleId waiting = m.add_bundle(m.add_applet("Waiting"), "a", {{a, kX}});
  const BundleId using_b = m.add_bundle(m.add_applet("User"), "b", {{b, kX}});
  Scheduler s(m);
  s.request(holder);
  s.request(waiting);
  s.set_deadline(waiting, Deadline{milliseconds{0}, milliseconds{1000}, milliseconds{3000}});
  s.request(using_b);
  s.set_deadline(using_b, Deadline{milliseconds{0}, milliseconds{100}, milliseconds{2000}});
  EXPECT_TRUE(s.active(using_b));
  s.take_notifications();
  s.advance_to(milliseconds{2500});
  EXPECT_FALSE(s.requested(using_b));
  EXPECT_TRUE(s.revoke_deadline(using_b).has_value());  // still in use until it yields
  auto notes = s.take_notifications();
  ASSERT_GE(notes.size(), 2u);
  EXPECT_EQ(notes[0].kind, Notification::Kind::kDeadlineExpired);
  EXPECT_EQ(notes[0].bundle, using_b);
  EXPECT_EQ(notes[0].until, milliseconds{2000});
  EXPECT_EQ(notes[1].kind, Notification::Kind::kRevokeRequested);
  EXPECT_EQ(notes[1].until, milliseconds{7000});  // the wait started at 2000 ms, not 2500 ms
  EXPECT_TRUE(s.requested(waiting));
  s.advance_to(milliseconds{3000});
  EXPECT_FALSE(s.requested(waiting));
  EXPECT_FALSE(s.deadline(waiting).has_value());
  s.release(holder);
  EXPECT_EQ(s.holder(a), "undef");  // the expired request is not granted later
}

TEST(Scheduler, PlanTakenBackCancelsTheRevocation) {
  TwoApplets t;
  Scheduler s(t.m);
  s.request(t.low);
  s.request(t.high);
  EXPECT_TRUE(s.revoke_deadline(t.low).has_value());
  s.release(t.high);
  EXPECT_FALSE(s.revoke_deadline(t.low).has_value());
  EXPECT_TRUE(s.active(t.low));
}

TEST(Scheduler, ServiceAppletGetsItsInheritedBundleHandedOver) {
  Model m;
  const ServiceId monitor = m.add_service("Monitor", true);
  const ServiceId ui = m.add_service("UI", true);
  const AppletId provider = m.add_applet("UIService");
  m.provide(provider, ui);
  const BundleId io = m.add_bundle(provider, "io", {{monitor, kX}});
  const BundleId menu = m.add_bundle(m.add_applet("Menu"), "ui", {{ui, kX}});
  Scheduler s(m);
  s.request(menu);  // the service applet never asked: inheritance grants its bundle
  EXPECT_FALSE(s.requested(io));
  EXPECT_TRUE(s.active(io));
  bool told = false;
  for (const Notification& n : s.take_notifications()) {
    told = told || (n.kind == Notification::Kind::kGranted && n.bundle == io);
  }
  EXPECT_TRUE(told);
  s.release(menu);
  EXPECT_TRUE(s.revoke_deadline(io).has_value());  // given back like any other bundle
  s.yield(io);
  EXPECT_FALSE(s.active(io));
}

TEST(Scheduler, CrashReleasesOnlyTheCrashedAppletsBundles) {
  Model m;
  const ServiceId a = m.add_service("A");
  const ServiceId b = m.add_service("B");
  const AppletId bad = m.add_applet("Bad");
  const BundleId ba = m.add_bundle(bad, "a", {{a, kX}});
  const BundleId good = m.add_bundle(m.add_applet("Good"), "b", {{b, kX}});
  const BundleId waiting = m.add_bundle(m.add_applet("Waiting"), "a", {{a, kX}});
  Scheduler s(m);
  s.request(ba);
  s.request(good);
  s.request(waiting);
  EXPECT_EQ(s.holder(a), "Bad");
  s.crash(bad);
  EXPECT_EQ(s.holder(a), "Waiting");
  EXPECT_TRUE(s.active(waiting));
  EXPECT_TRUE(s.active(good));
  EXPECT_FALSE(s.requested(ba));
}

// A service whose modules failed goes away for a while (the coordinator, docs/coordinator.md):
// its users, also down the hierarchy, lose it at once and are told; they keep their request and
// get it back when it returns.
TEST(Scheduler, AServiceAwayForAWhileIsTakenFromItsUsersAndGrantedAgainWhenBack) {
  Model m;
  const ServiceId camera = m.add_service("Camera", true);
  const ServiceId tracker = m.add_service("Tracker");
  m.add_dependency(tracker, camera);
  const BundleId track = m.add_bundle(m.add_applet("Follow"), "t", {{tracker, kX}});
  Scheduler s(m);
  s.request(track);
  ASSERT_TRUE(s.active(track));
  s.take_notifications();
  s.set_available(camera, false);
  EXPECT_FALSE(s.available(camera));
  EXPECT_FALSE(s.active(track));
  EXPECT_TRUE(s.requested(track));
  EXPECT_EQ(s.holder(camera), "unavailable");
  bool told = false;
  for (const Notification& n : s.take_notifications()) {
    told = told || (n.kind == Notification::Kind::kRevokedByForce && n.bundle == track &&
                    n.service == camera);
  }
  EXPECT_TRUE(told);
  s.set_available(camera, true);
  EXPECT_TRUE(s.available(camera));
  EXPECT_TRUE(s.active(track));
  EXPECT_EQ(s.holder(tracker), "Follow");
}

TEST(Scheduler, ACrashedServiceAppletsServiceDoesNotComeBack) {
  Model m;
  const ServiceId ui = m.add_service("UI", true);
  const AppletId provider = m.add_applet("UIService");
  m.provide(provider, ui);
  m.add_bundle(provider, "io", {{m.add_service("Monitor"), kX}});
  Scheduler s(m);
  s.crash(provider);
  s.set_available(ui, true);
  EXPECT_FALSE(s.available(ui));
}

// Seed §4.6.1 (cascading effects): when a service applet crashes, its services are gone. Its
// resources used to be granted again through inheritance, and the users of its service kept
// their grant; now the users lose it at once (told, naming the service), keep their request,
// and what the service applet held is free for others.
TEST(Scheduler, CrashedServiceAppletsServicesBecomeUnavailableAndTheirUsersLoseThem) {
  Model m;
  const ServiceId monitor = m.add_service("Monitor", true);
  const ServiceId ui = m.add_service("UI", true);
  const ServiceId menu_view = m.add_service("MenuView");
  m.add_dependency(menu_view, ui);  // down the hierarchy: MenuView needs UI
  const AppletId provider = m.add_applet("UIService");
  m.provide(provider, ui);
  const BundleId io = m.add_bundle(provider, "io", {{monitor, kX}});
  const BundleId menu = m.add_bundle(m.add_applet("Menu"), "ui", {{ui, kX}}, kPriorityHigh);
  const BundleId viewer = m.add_bundle(m.add_applet("Viewer"), "v", {{menu_view, kX}});
  const BundleId screen = m.add_bundle(m.add_applet("Screen"), "m", {{monitor, kX}}, kPriorityLow);
  Scheduler s(m);
  s.request(menu);
  s.request(screen);
  EXPECT_TRUE(s.active(menu));
  EXPECT_TRUE(s.active(io));       // inherited
  EXPECT_FALSE(s.active(screen));  // the service applet holds the monitor
  s.take_notifications();
  s.crash(provider);
  EXPECT_TRUE(s.crashed(provider));
  EXPECT_FALSE(s.available(ui));
  EXPECT_FALSE(s.active(menu));
  EXPECT_TRUE(s.requested(menu));
  EXPECT_FALSE(s.plan().bundle_granted[io]);
  EXPECT_FALSE(s.active(io));
  EXPECT_EQ(s.holder(ui), "unavailable");
  EXPECT_TRUE(s.active(screen));  // the monitor is free again
  EXPECT_EQ(s.holder(monitor), "Screen");
  bool told = false;
  for (const Notification& n : s.take_notifications()) {
    told = told ||
           (n.kind == Notification::Kind::kRevokedByForce && n.bundle == menu && n.service == ui);
  }
  EXPECT_TRUE(told);
  s.request(viewer);  // needs UI down the hierarchy: cannot be granted
  EXPECT_FALSE(s.plan().bundle_granted[viewer]);
  EXPECT_EQ(s.holder(menu_view), "blocked");
  EXPECT_THAT(error_of([&] { s.request(io); }),
              HasSubstr("applet 'UIService' requests bundle 'io' but it crashed"));
}

}  // namespace
}  // namespace oscar::applets
