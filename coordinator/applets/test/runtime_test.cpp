// The threaded runtime. No test depends on timing beyond "eventually, within seconds".
#include "oscar/applets/runtime.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_support.hpp"

#include <atomic>
#include <functional>
#include <mutex>
#include <thread>

namespace oscar::applets {
namespace {

using namespace std::chrono_literals;
constexpr auto kX = Access::kExclusive;
constexpr auto kS = Access::kShared;

using testing::eventually;

// The service of the appendix test case: increment and read, synchronised by a mutex.
class CounterService {
 public:
  void increment() {
    std::lock_guard lock(mutex_);
    ++counter_;
  }
  long get() const {
    std::lock_guard lock(mutex_);
    return counter_;
  }

 private:
  mutable std::mutex mutex_;
  long counter_ = 0;
};

// Seed 000 appendix A: two applets increment a shared counter service; applet 1 switches
// between shared and exclusive; pausing releases, resuming requests again.
TEST(Runtime, AppendixCountersAddUpAcrossSharedAndExclusiveAccess) {
  Model m;
  const ServiceId svc = m.add_service("Counter");
  const AppletId a1 = m.add_applet("App1");
  const AppletId a2 = m.add_applet("App2");
  m.add_bundle(a1, "shared", {{svc, kS}});
  m.add_bundle(a1, "exclusive", {{svc, kX}});
  m.add_bundle(a2, "shared", {{svc, kS}});
  Runtime rt(m);
  CounterService service;
  std::atomic<long> c1{0}, c2{0};
  std::atomic<bool> exclusive1{false};
  auto code = [&](std::atomic<long>& mine, bool first) {
    AppletCode c;
    c.init = [](AppletContext& ctx) { ctx.request("shared"); };
    c.step = [&, first](AppletContext& ctx) {
      const std::string bundle = first && exclusive1 ? "exclusive" : "shared";
      ctx.use(bundle, [&] {
        service.increment();
        ++mine;
      });
    };
    c.period = 2ms;
    return c;
  };
  rt.set_code("App1", code(c1, true));
  rt.set_code("App2", code(c2, false));
  auto pause = [&](const char* applet, const char* bundle) {
    rt.pause(applet, true);
    rt.with_scheduler(
        [&](Scheduler& s) { s.release(s.model().bundle_id(s.model().applet_id(applet), bundle)); });
  };
  auto resume = [&](const char* applet, const char* bundle) {
    rt.with_scheduler(
        [&](Scheduler& s) { s.request(s.model().bundle_id(s.model().applet_id(applet), bundle)); });
    rt.pause(applet, false);
  };
  auto settle = [&] {  // both threads pass a few loops: a step under way has ended
    const long a = c2.load();
    std::this_thread::sleep_for(30ms);
    return a;
  };
  rt.start();
  ASSERT_TRUE(eventually([&] { return c1 > 5 && c2 > 5; }));
  // Steps 2–5: pause applet 1; its counter stands still while applet 2 goes on.
  pause("App1", "shared");
  settle();
  const long saved1 = c1;
  const long from2 = c2;
  ASSERT_TRUE(eventually([&] { return c2 > from2 + 20; }));
  EXPECT_EQ(c1.load(), saved1);
  resume("App1", "shared");
  ASSERT_TRUE(eventually([&] { return c1 > saved1 + 5; }));
  // Step 5: counter sums (both paused so the figures stand still).
  pause("App1", "shared");
  pause("App2", "shared");
  settle();
  EXPECT_EQ(c1 + c2, service.get());
  // Steps 6–12: applet 1 exclusive, resumed before applet 2: only applet 1 counts.
  exclusive1 = true;
  resume("App1", "exclusive");
  resume("App2", "shared");
  const long saved2 = c2;
  const long before1 = c1;
  ASSERT_TRUE(eventually([&] { return c1 > before1 + 30; }));
  EXPECT_EQ(c2.load(), saved2);
  EXPECT_EQ(c1 + c2, service.get());
  // Steps 13–16: applet 1 shared again: applet 2 counts again.
  rt.with_scheduler([&](Scheduler& s) {
    s.release(s.model().bundle_id(a1, "exclusive"));
    exclusive1 = false;
    s.request(s.model().bundle_id(a1, "shared"));
  });
  ASSERT_TRUE(eventually([&] { return c2 > saved2 + 5; }));
  pause("App1", "shared");
  pause("App2", "shared");
  settle();
  EXPECT_EQ(c1 + c2, service.get());
  rt.stop();
  EXPECT_GT(rt.stats().grants, 4u);
}

// Abb. 4.12/4.14: the scheduler only queues handlers; the applet's own thread runs them between
// two steps, never during one, and never the thread that changed the plan.
TEST(Runtime, InterruptHandlersRunOnTheAppletThreadBetweenSteps) {
  Model m;
  const ServiceId s = m.add_service("S");
  m.add_bundle(m.add_applet("Holder"), "s", {{s, kX}});
  const BundleId high = m.add_bundle(m.add_applet("Urgent"), "s", {{s, kX}}, kPriorityHigh);
  Runtime rt(m);
  std::mutex mu;
  std::thread::id step_thread, handler_thread;
  std::atomic<bool> in_step{false}, handled{false}, during_step{false};
  std::atomic<int> steps{0};
  rt.set_code("Holder", {[](AppletContext& c) { c.request("s"); },
                         [&](AppletContext& c) {
                           in_step = true;
                           {
                             std::lock_guard lock(mu);
                             step_thread = std::this_thread::get_id();
                           }
                           if (c.granted("s")) c.use("s", [] {});
                           ++steps;
                           in_step = false;
                         },
                         [&](AppletContext& c, const Notification& n) {
                           during_step = during_step || in_step;
                           {
                             std::lock_guard lock(mu);
                             handler_thread = std::this_thread::get_id();
                           }
                           if (n.kind == Notification::Kind::kRevokeRequested) {
                             c.yield("s");
                             handled = true;
                           }
                         },
                         2ms});
  rt.start();
  ASSERT_TRUE(eventually([&] { return steps > 2; }));
  rt.with_scheduler([&](Scheduler& sch) { sch.request(high); });
  ASSERT_TRUE(eventually([&] { return handled.load(); }));
  rt.stop();
  EXPECT_FALSE(during_step.load());
  std::lock_guard lock(mu);
  EXPECT_EQ(handler_thread, step_thread);
  EXPECT_NE(handler_thread, std::this_thread::get_id());
}

// An interrupt does not wait for the applet's next step: an applet stepping every 30 s hears of
// its grant and of a revocation at once, and yields without having stepped again.
TEST(Runtime, AnInterruptRunsAtOnceNotAtTheNextStep) {
  Model m;
  const ServiceId s = m.add_service("S");
  m.add_bundle(m.add_applet("Slow"), "s", {{s, kX}});
  const BundleId high = m.add_bundle(m.add_applet("Urgent"), "s", {{s, kX}}, kPriorityHigh);
  Runtime rt(m);
  std::atomic<int> steps{0};
  std::atomic<bool> granted{false}, yielded{false};
  rt.set_code("Slow", {[](AppletContext& c) { c.request("s"); }, [&](AppletContext&) { ++steps; },
                       [&](AppletContext& c, const Notification& n) {
                         if (n.kind == Notification::Kind::kGranted) granted = true;
                         if (n.kind == Notification::Kind::kRevokeRequested) {
                           c.yield("s");
                           yielded = true;
                         }
                       },
                       30s});
  rt.start();
  ASSERT_TRUE(eventually([&] { return granted.load(); }));
  rt.with_scheduler([&](Scheduler& sch) { sch.request(high); });
  ASSERT_TRUE(eventually([&] { return yielded.load(); }));
  std::string holder;
  rt.with_scheduler([&](Scheduler& sch) { holder = sch.holder(s); });
  EXPECT_EQ(holder, "Urgent");
  EXPECT_EQ(steps.load(), 1);  // the first, at start; the next is 30 s away
  rt.stop();
}

TEST(Runtime, CrashedAppletLosesItsResourcesAndNothingElseIsAffected) {
  Model m;
  const ServiceId s = m.add_service("S");
  const ServiceId other = m.add_service("Other");
  m.add_bundle(m.add_applet("Bad"), "s", {{s, kX}}, kPriorityHigh);
  m.add_bundle(m.add_applet("Waiting"), "s", {{s, kX}});
  m.add_bundle(m.add_applet("Bystander"), "o", {{other, kX}});
  Runtime rt(m);
  std::atomic<int> bad_steps{0}, waiting_uses{0}, bystander{0};
  rt.set_code("Bad", {[](AppletContext& c) { c.request("s"); },
                      [&](AppletContext& c) {
                        c.use("s", [&] {
                          if (++bad_steps == 5) throw std::runtime_error("applet bug");
                        });
                      },
                      {},
                      2ms});
  rt.set_code("Waiting", {[](AppletContext& c) { c.request("s"); },
                          [&](AppletContext& c) { c.use("s", [&] { ++waiting_uses; }); },
                          {},
                          2ms});
  rt.set_code("Bystander", {[](AppletContext& c) { c.request("o"); },
                            [&](AppletContext& c) { c.use("o", [&] { ++bystander; }); },
                            {},
                            2ms});
  rt.start();
  ASSERT_TRUE(eventually([&] { return waiting_uses > 3; }));
  EXPECT_TRUE(rt.crashed("Bad"));
  EXPECT_FALSE(rt.crashed("Waiting"));
  EXPECT_EQ(bad_steps.load(), 5);
  const int b = bystander;
  ASSERT_TRUE(eventually([&] { return bystander > b + 3; }));
  rt.stop();
  EXPECT_EQ(rt.stats().crashed, std::vector<std::string>{"Bad"});
}

// The wrapper is the applet's boundary: a thrown value that is no std::exception ends the applet
// too, not the process.
TEST(Runtime, AppletThrowingANonStandardExceptionCrashesAloneAndLosesItsResources) {
  Model m;
  const ServiceId s = m.add_service("S");
  m.add_bundle(m.add_applet("Bad"), "s", {{s, kX}}, kPriorityHigh);
  m.add_bundle(m.add_applet("Waiting"), "s", {{s, kX}});
  Runtime rt(m);
  std::atomic<int> bad_steps{0}, waiting_uses{0};
  rt.set_code("Bad", {[](AppletContext& c) { c.request("s"); },
                      [&](AppletContext& c) {
                        c.use("s", [&] {
                          if (++bad_steps == 3) throw 42;
                        });
                      },
                      {},
                      2ms});
  rt.set_code("Waiting", {[](AppletContext& c) { c.request("s"); },
                          [&](AppletContext& c) { c.use("s", [&] { ++waiting_uses; }); },
                          {},
                          2ms});
  rt.start();
  // "Waiting" may hold the service before "Bad" first asks: what counts is its uses after the
  // crash, which only the crashed applet's lost grant allows.
  ASSERT_TRUE(eventually([&] { return rt.crashed("Bad"); }));
  const int before = waiting_uses;
  ASSERT_TRUE(eventually([&] { return waiting_uses > before + 3; }));
  EXPECT_EQ(bad_steps.load(), 3);
  rt.stop();
  EXPECT_EQ(rt.stats().crashed, std::vector<std::string>{"Bad"});
}

// Seed §4.5.2, footnote 11: answering a revocation with a new priority (or a trigger) would make
// the plan oscillate; the runtime refuses both from a revocation's interrupt handler, while the
// same calls in a main-loop step are fine.
TEST(Runtime, ReprioritisingInReactionToARevocationIsRefused) {
  Model m;
  const ServiceId s = m.add_service("S");
  m.add_bundle(m.add_applet("Holder"), "s", {{s, kX}});
  const BundleId urgent = m.add_bundle(m.add_applet("Urgent"), "s", {{s, kX}}, kPriorityHigh);
  Runtime rt(m);
  std::mutex mu;
  std::vector<std::string> refused;
  std::atomic<bool> raised_in_step{false}, handled{false};
  rt.set_code("Holder",
              {[](AppletContext& c) { c.request("s"); },
               [&](AppletContext& c) {
                 if (!raised_in_step) {
                   c.set_priority("s", kPriorityNormal + 1);  // outside a handler: allowed
                   raised_in_step = true;
                 }
               },
               [&](AppletContext& c, const Notification& n) {
                 if (n.kind != Notification::Kind::kRevokeRequested) return;
                 for (const auto& call : std::vector<std::function<void()>>{
                          [&] { c.set_priority("s", kPrioritySystem); }, [&] { c.trigger("s"); }}) {
                   try {
                     call();
                   } catch (const std::invalid_argument& e) {
                     std::lock_guard lock(mu);
                     refused.emplace_back(e.what());
                   }
                 }
                 c.yield("s");
                 handled = true;
               },
               2ms});
  rt.start();
  ASSERT_TRUE(eventually([&] { return raised_in_step.load(); }));
  rt.with_scheduler([&](Scheduler& sch) { sch.request(urgent); });
  ASSERT_TRUE(eventually([&] { return handled.load(); }));
  ASSERT_TRUE(eventually([&] {
    bool active = false;
    rt.with_scheduler([&](Scheduler& sch) { active = sch.active(urgent); });
    return active;
  }));
  int holder_priority = 0;
  rt.with_scheduler([&](Scheduler& sch) { holder_priority = sch.priority(0); });
  rt.stop();
  EXPECT_EQ(holder_priority, kPriorityNormal + 1);
  std::lock_guard lock(mu);
  ASSERT_EQ(refused.size(), 2u);
  EXPECT_THAT(refused[0], ::testing::HasSubstr(
                              "applet 'Holder' changes the priority of bundle 's' while it reacts "
                              "to the revocation of its bundle 's'"));
  EXPECT_THAT(refused[0], ::testing::HasSubstr("footnote 11"));
  EXPECT_THAT(refused[1], ::testing::HasSubstr("applet 'Holder' triggers bundle 's'"));
}

// The runtime's clock thread plans again at a reservation's t_early: the bundle is granted then,
// with nothing else happening, and not before (the grant is stamped with the scheduler's time).
TEST(Runtime, ReservationIsGrantedAtItsEarliestStartWithoutAnyOtherCall) {
  Model m;
  const ServiceId s = m.add_service("S");
  m.add_bundle(m.add_applet("Later"), "s", {{s, kX}});
  Runtime rt(m);
  std::atomic<long long> granted_at{-1}, t_early{-1};
  rt.set_code("Later", {[&](AppletContext& c) {
                          milliseconds now{0};
                          rt.with_scheduler([&](Scheduler& sch) { now = sch.now(); });
                          t_early = (now + 300ms).count();
                          c.set_deadline("s", Deadline{now + 300ms, 100ms, now + 10s});
                          c.request("s");
                        },
                        [](AppletContext&) {},
                        [&](AppletContext&, const Notification& n) {
                          if (n.kind == Notification::Kind::kGranted) granted_at = n.until.count();
                        },
                        2ms});
  rt.start();
  ASSERT_TRUE(eventually([&] { return granted_at >= 0; }));
  rt.stop();
  EXPECT_GE(granted_at.load(), t_early.load());
}

TEST(Runtime, HolderThatDoesNotYieldIsRevokedByForceAndToldWhoGetsIt) {
  Model m;
  const ServiceId s = m.add_service("S");
  m.add_bundle(m.add_applet("Stubborn"), "s", {{s, kX}});
  const BundleId high = m.add_bundle(m.add_applet("Urgent"), "s", {{s, kX}}, kPriorityHigh);
  SchedulerOptions o;
  o.revoke_wait = 100ms;
  Runtime rt(m, o);
  std::mutex mu;
  std::vector<Notification> seen;
  std::atomic<int> urgent{0};
  rt.set_code("Stubborn", {[](AppletContext& c) { c.request("s"); },
                           [](AppletContext& c) { c.use("s", [] {}); },
                           [&](AppletContext&, const Notification& n) {
                             std::lock_guard lock(mu);
                             seen.push_back(n);  // does not yield
                           },
                           2ms});
  rt.set_code("Urgent", {{}, [&](AppletContext& c) { c.use("s", [&] { ++urgent; }); }, {}, 2ms});
  rt.start();
  ASSERT_TRUE(eventually([&] {
    std::lock_guard lock(mu);
    return !seen.empty();
  }));
  rt.with_scheduler([&](Scheduler& sch) { sch.request(high); });
  ASSERT_TRUE(eventually([&] { return urgent > 0; }));
  ASSERT_TRUE(eventually([&] {  // the handler runs at Stubborn's next loop
    std::lock_guard lock(mu);
    return seen.back().kind == Notification::Kind::kRevokedByForce;
  }));
  rt.stop();
  std::lock_guard lock(mu);
  bool told = false, forced = false;
  for (const Notification& n : seen) {
    if (n.kind == Notification::Kind::kRevokeRequested) {
      told = n.new_holders == std::vector<AppletId>{m.bundle(high).applet};
    }
    forced = forced || n.kind == Notification::Kind::kRevokedByForce;
  }
  EXPECT_TRUE(told);
  EXPECT_TRUE(forced);
}

TEST(Runtime, FailStopAppletGetsAnExceptionInsteadOfBlocking) {
  Model m;
  const ServiceId s = m.add_service("S");
  m.add_bundle(m.add_applet("Holder"), "s", {{s, kX}}, kPriorityHigh);
  m.add_bundle(m.add_applet("Careful", true), "s", {{s, kX}});
  Runtime rt(m);
  std::atomic<int> refused{0};
  rt.set_code("Holder", {[](AppletContext& c) { c.request("s"); },
                         [](AppletContext& c) { c.use("s", [] {}); },
                         {},
                         2ms});
  rt.set_code("Careful", {[](AppletContext& c) { c.request("s"); },
                          [&](AppletContext& c) {
                            try {
                              c.use("s", [] {});
                            } catch (const ResourceRevoked&) {
                              ++refused;
                            }
                          },
                          {},
                          2ms});
  rt.start();
  ASSERT_TRUE(eventually([&] { return refused > 3; }));
  rt.stop();
  EXPECT_FALSE(rt.crashed("Careful"));
}

}  // namespace
}  // namespace oscar::applets

namespace oscar::applets {
namespace {

// An applet whose code runs in another process has no thread here: its notifications go to
// the forwarder, in order, and its bundles move by scheduler calls (what the coordinator does
// with an applet's messages over DDS).
TEST(Runtime, ARemoteAppletsNotificationsGoToItsForwarderAndItRunsNoCodeHere) {
  Model m;
  const ServiceId s = m.add_service("S");
  const BundleId remote =
      m.add_bundle(m.add_applet("Remote"), "s", {{s, Access::kExclusive}}, kPriorityHigh);
  m.add_bundle(m.add_applet("Local"), "s", {{s, Access::kExclusive}});
  Runtime rt(m);
  std::mutex mu;
  std::vector<Notification::Kind> forwarded;
  rt.set_remote("Remote", [&](const Notification& n) {
    std::lock_guard lock(mu);
    forwarded.push_back(n.kind);
  });
  EXPECT_THROW(rt.set_code("Remote", {{}, [](AppletContext&) {}, {}, std::chrono::milliseconds(2)}),
               std::invalid_argument);
  std::atomic<int> local_uses{0};
  rt.set_code("Local", {[](AppletContext& c) { c.request("s"); },
                        [&](AppletContext& c) { c.use("s", [&] { ++local_uses; }); },
                        {},
                        std::chrono::milliseconds(2)});
  rt.start();
  ASSERT_TRUE(testing::eventually([&] { return local_uses > 0; }));
  rt.with_scheduler([&](Scheduler& sch) { sch.request(remote); });
  // The local holder yields by default; the remote bundle is granted.
  ASSERT_TRUE(testing::eventually([&] {
    bool active = false;
    rt.with_scheduler([&](Scheduler& sch) { active = sch.active(remote); });
    return active;
  }));
  {
    std::lock_guard lock(mu);
    EXPECT_EQ(forwarded, std::vector<Notification::Kind>{Notification::Kind::kGranted});
  }
  rt.with_scheduler([&](Scheduler& sch) { sch.release(remote); });
  const int before = local_uses;
  ASSERT_TRUE(testing::eventually([&] { return local_uses > before; }));
  rt.stop();
}

}  // namespace
}  // namespace oscar::applets
