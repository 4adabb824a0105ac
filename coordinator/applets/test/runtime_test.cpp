// The threaded runtime. No test depends on timing beyond "eventually, within seconds".
#include "oscar/applets/runtime.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <thread>

namespace oscar::applets {
namespace {

using namespace std::chrono_literals;
constexpr auto kX = Access::kExclusive;
constexpr auto kS = Access::kShared;

template <typename P>
bool eventually(P pred, std::chrono::milliseconds limit = 10s) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(2ms);
  }
  return pred();
}

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

// Seed §4.5.3: the docked battery applet asks for time, and in the accepted follow-up round
// undocks before the drive gets the pilot; a rejected vote runs the reject round instead. The
// battery's bundle hears from two reassigners (Dock and, down the hierarchy, Pilot) and starts
// one chain only.
TEST(Runtime, NegotiationRoundsRunTheirCodeBeforeTheHandOver) {
  for (const bool vote : {true, false}) {
    Model m;
    const ServiceId pilot = m.add_service("Pilot");
    const ServiceId dock = m.add_service("Dock");
    m.add_dependency(dock, pilot);
    m.add_bundle(m.add_applet("Battery"), "dock", {{dock, kX}});
    const BundleId drive = m.add_bundle(m.add_applet("DriveTo"), "p", {{pilot, kX}}, kPriorityHigh);
    Runtime rt(m);
    std::atomic<bool> undocked{false}, stopped_hard{false}, docked{false};
    std::atomic<int> drives_docked{0}, drives{0}, chains{0}, revoke_notices{0};
    std::atomic<int> reply{-1};
    rt.set_code("Battery", {[](AppletContext& c) { c.request("dock"); },
                            [&](AppletContext& c) { c.use("dock", [&] { docked = true; }); },
                            [&, vote](AppletContext& c, const Notification& n) {
                              if (n.kind == Notification::Kind::kNegotiationAccepted ||
                                  n.kind == Notification::Kind::kNegotiationRejected) {
                                reply = static_cast<int>(n.kind);
                              }
                              if (n.kind != Notification::Kind::kRevokeRequested) return;
                              ++revoke_notices;
                              auto undock = std::make_shared<NegotiationRound>();
                              undock->first = [&] { undocked = true; };
                              undock->answer = {0ms, 0ms, true};
                              auto hard = std::make_shared<NegotiationRound>();
                              hard->first = [&] { stopped_hard = true; };
                              NegotiationRound ask{{50ms, 200ms, vote}, {}, undock, hard};
                              if (c.negotiate("dock", ask)) ++chains;
                            },
                            2ms});
    rt.set_code("DriveTo", {{},
                            [&](AppletContext& c) {
                              c.use("p", [&] {
                                ++drives;
                                if (!undocked && !stopped_hard) ++drives_docked;
                              });
                            },
                            {},
                            2ms});
    rt.start();
    ASSERT_TRUE(eventually([&] { return docked.load(); }));
    rt.with_scheduler([&](Scheduler& s) { s.request(drive); });
    ASSERT_TRUE(eventually([&] { return drives > 0; }));
    rt.stop();
    EXPECT_EQ(drives_docked.load(), 0) << "the pilot moved while docked";
    EXPECT_EQ(undocked.load(), vote);
    EXPECT_EQ(stopped_hard.load(), !vote);
    EXPECT_EQ(revoke_notices.load(), 2);  // the reassigners of Dock and Pilot
    EXPECT_EQ(chains.load(), 1);
    // The last reply: the undock round's "accept, no time" is accepted; the reject round
    // answers with the default (a vote against), which is rejected.
    EXPECT_EQ(reply.load(), static_cast<int>(vote ? Notification::Kind::kNegotiationAccepted
                                                  : Notification::Kind::kNegotiationRejected));
  }
}

// A holder and a taker of one service; the holder answers a revocation with `chain`.
struct NegotiationRun {
  Model m;
  ServiceId s = m.add_service("S");
  BundleId held = m.add_bundle(m.add_applet("Holder"), "s", {{s, kX}});
  BundleId taker = m.add_bundle(m.add_applet("Taker"), "s", {{s, kX}}, kPriorityHigh);
  std::atomic<std::uint64_t> steps{0};
  std::atomic<int> answers{0};
  std::atomic<bool> taken{false};
  std::mutex mu;
  std::vector<std::uint64_t> round_steps;  // the holder's step count when each round ran

  // Runs until the taker uses the service; `chain` gets a round recorder per round.
  // Waits for `replies` answers to reach the holder.
  void run(SchedulerOptions o, int rounds, int replies,
           std::chrono::milliseconds first_takes = 0ms) {
    std::shared_ptr<NegotiationRound> chain;
    for (int i = 0; i < rounds; ++i) {
      auto r = std::make_shared<NegotiationRound>();
      r->answer = {0ms, 5000ms, true};
      r->first = [this, first_takes] {
        {
          std::lock_guard lock(mu);
          round_steps.push_back(steps.load());
        }
        std::this_thread::sleep_for(first_takes);
      };
      r->on_accept = chain;
      r->on_reject = chain;
      chain = r;
    }
    Runtime rt(m, o);
    rt.set_code("Holder", {[](AppletContext& c) { c.request("s"); },
                           [this](AppletContext& c) {
                             ++steps;  // never blocks: the loop goes on to take the replies
                             if (c.granted("s")) c.use("s", [] {});
                           },
                           [this, chain](AppletContext& c, const Notification& n) {
                             if (n.kind == Notification::Kind::kNegotiationAccepted ||
                                 n.kind == Notification::Kind::kNegotiationRejected) {
                               ++answers;
                             }
                             if (n.kind == Notification::Kind::kRevokeRequested) {
                               c.negotiate("s", *chain);
                             }
                           },
                           2ms});
    rt.set_code("Taker",
                {{}, [this](AppletContext& c) { c.use("s", [this] { taken = true; }); }, {}, 2ms});
    rt.start();
    ASSERT_TRUE(eventually([&] { return steps > 0; }));
    rt.with_scheduler([&](Scheduler& sch) { sch.request(taker); });
    ASSERT_TRUE(eventually([&] { return taken.load(); }));
    eventually([&] { return answers >= replies; }, 2s);
    rt.stop();
  }
};

// Abb. 4.12 and §4.5.3: follow-up rounds are interrupt handlers, so each runs between two later
// main-loop steps, never back to back with the round before it.
TEST(Runtime, FollowUpRoundsRunAtLaterMainLoopSteps) {
  NegotiationRun r;
  SchedulerOptions o;
  o.negotiation_rounds_max = 4;
  r.run(o, 4, 4);
  std::lock_guard lock(r.mu);
  ASSERT_EQ(r.round_steps.size(), 4u);
  for (std::size_t i = 1; i < r.round_steps.size(); ++i) {
    EXPECT_GT(r.round_steps[i], r.round_steps[i - 1]) << "round " << i;
  }
  EXPECT_EQ(r.answers.load(), 4);
}

TEST(Runtime, NegotiationStopsAfterTheConfiguredNumberOfRounds) {
  NegotiationRun r;
  SchedulerOptions o;
  o.negotiation_rounds_max = 2;
  r.run(o, 5, 2);
  std::lock_guard lock(r.mu);
  EXPECT_EQ(r.round_steps.size(), 2u);  // then the bundle was handed over
  EXPECT_EQ(r.answers.load(), 2);
}

// A round whose code takes longer than the round limit is not answered and ends the chain.
// (The sleep can only make the round longer, so it cannot make this test pass wrongly.)
TEST(Runtime, RoundOverTheTimeLimitEndsTheNegotiation) {
  NegotiationRun r;
  SchedulerOptions o;
  o.negotiation_round_max = 50ms;
  r.run(o, 3, 1, 150ms);
  std::lock_guard lock(r.mu);
  EXPECT_EQ(r.round_steps.size(), 1u);
  EXPECT_EQ(r.answers.load(), 0);
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
