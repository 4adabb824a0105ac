// Negotiation rounds in the threaded runtime (seed 000 §4.5.3, Abb. 4.12): AppletContext runs
// a chain of rounds, one per main-loop step. No test depends on timing beyond "eventually".
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <thread>

#include "oscar/applets/runtime.hpp"
#include "test_support.hpp"

namespace oscar::applets {
namespace {

using namespace std::chrono_literals;
using testing::eventually;
constexpr auto kX = Access::kExclusive;

// Seed §4.5.3: the docked battery applet asks for 50 ms to 30 s, and in the accepted follow-up
// round undocks before the drive gets the pilot. Agreeing to the revocation, it is given the
// 50 ms (30 s is more than a round may grant); objecting to it, it insists on the 30 s, is
// rejected and runs the reject round instead. The
// battery's bundle hears from two reassigners (Dock and, down the hierarchy, Pilot) and starts
// one chain only.
TEST(Negotiation, RoundsRunTheirCodeBeforeTheHandOver) {
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
                              if ((n.kind == Notification::Kind::kNegotiationAccepted ||
                                   n.kind == Notification::Kind::kNegotiationRejected) &&
                                  reply < 0) {
                                reply = static_cast<int>(n.kind);  // the first round's reply
                              }
                              if (n.kind != Notification::Kind::kRevokeRequested) return;
                              ++revoke_notices;
                              auto undock = std::make_shared<NegotiationRound>();
                              undock->first = [&] { undocked = true; };
                              undock->answer = {0ms, 0ms, true};
                              auto hard = std::make_shared<NegotiationRound>();
                              hard->first = [&] { stopped_hard = true; };
                              NegotiationRound ask{{50ms, 30s, vote}, {}, undock, hard};
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
    // The first round's reply follows its vote.
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
TEST(Negotiation, FollowUpRoundsRunAtLaterMainLoopSteps) {
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

TEST(Negotiation, StopsAfterTheConfiguredNumberOfRounds) {
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
TEST(Negotiation, RoundOverTheTimeLimitEndsTheNegotiation) {
  NegotiationRun r;
  SchedulerOptions o;
  o.negotiation_round_max = 50ms;
  r.run(o, 3, 1, 150ms);
  std::lock_guard lock(r.mu);
  EXPECT_EQ(r.round_steps.size(), 1u);
  EXPECT_EQ(r.answers.load(), 0);
}

}  // namespace
}  // namespace oscar::applets
