// A coordinator that restarts takes over its robots' committed plans (docs/swarm.md, "A
// coordinator that restarts"): killed while a robot drives to a job far away, the registry
// restarts it, and the new one knows where that robot will drive and what it will work, shows
// the job, plans new jobs from where the robot will really be (no NAK), keeps every committed
// path clear of the others, and the robot does its job at its place within its window.
#include <signal.h>

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "swarm_client.hpp"

namespace oscar {
namespace {

using namespace std::chrono_literals;
using test::job;

// r1 drives at 1 m/s; r2 stands far off, a candidate for every job.
constexpr const char* kSystem = R"(
system: swarm_restart
modules:
  - name: robots
    mode: { continuous: 50ms }
    kernels:
      - { type: robot_sim, name: r1, params: { start_x: 0, start_y: 0, max_speed: 1 } }
      - { type: robot_sim, name: r2, params: { start_x: 0, start_y: 20, max_speed: 1 },
          mode: { single_step: { trigger: module } } }
  - name: monitor
    mode: { continuous: 50ms }
    kernels:
      - { type: safety_monitor, name: safety, inputs: { r1: r1/state, r2: r2/state } }
coordinator:
  swarm:
    frozen_horizon_ms: 1500
    ack_timeout_ms: 500
)";

const SwarmPlacedJob* find_job(const SwarmStatus& s, const std::string& id) {
  const auto it = std::find_if(s.jobs().begin(), s.jobs().end(),
                               [&](const SwarmPlacedJob& j) { return j.id() == id; });
  return it == s.jobs().end() ? nullptr : &*it;
}

bool in_planning(const SwarmStatus& s, const std::string& robot) {
  return std::find(s.robots().begin(), s.robots().end(), robot) != s.robots().end();
}

// Where a path is at time t (before its first waypoint at that one, after its last at that one).
std::pair<double, double> at(const SwarmPath& p, Stamp t) {
  const auto& w = p.waypoints();
  if (t <= w.front().t_ns()) return {w.front().x(), w.front().y()};
  for (std::size_t i = 1; i < w.size(); ++i) {
    if (t <= w[i].t_ns()) {
      const double u = static_cast<double>(t - w[i - 1].t_ns()) /
                       static_cast<double>(std::max<Stamp>(1, w[i].t_ns() - w[i - 1].t_ns()));
      return {w[i - 1].x() + u * (w[i].x() - w[i - 1].x()),
              w[i - 1].y() + u * (w[i].y() - w[i - 1].y())};
    }
  }
  return {w.back().x(), w.back().y()};
}

class SwarmRestart : public ::testing::Test {
 protected:
  SwarmRestart()
      : system_("swarm_restart", kSystem),
        violations_(system_.watch<SafetyViolation>("safety/violations")) {
    system_.running();
    client_ = std::make_unique<test::SwarmClient>(system_.participant(), "swarm_restart_test");
  }

  // Kills the coordinator and waits until the registry has it running again.
  void restart_coordinator() {
    const auto s = system_.wait_for([](const SystemState& st) {
      const auto* m = test::entry(st, "coordinator");
      return m && m->status() == "running";
    });
    const auto* m = test::entry(s, "coordinator");
    ASSERT_NE(m, nullptr);
    const auto first = m->incarnation();
    ASSERT_EQ(kill(static_cast<pid_t>(m->pid()), SIGKILL), 0);
    system_.wait_for([&](const SystemState& st) {
      const auto* c = test::entry(st, "coordinator");
      return c && c->incarnation() > first && c->status() == "running";
    });
  }

  // Nothing brought the robots too close or off their jobs, by the safety monitor's account.
  void TearDown() override {
    std::this_thread::sleep_for(300ms);
    for (const auto& v : violations_->take()) {
      ADD_FAILURE() << "safety violation " << v.kind() << ": " << v.detail();
    }
  }

  test::BootedSystem system_;
  std::unique_ptr<testing::CueWatch<SafetyViolation>> violations_;
  std::unique_ptr<test::SwarmClient> client_;
};

TEST_F(SwarmRestart, TheNewCoordinatorTakesOverTheRobotsCommittedPlans) {
  client_->status([](const SwarmStatus& s) { return in_planning(s, "r1") && in_planning(s, "r2"); },
                  "r1 and r2 in planning");
  // r1 drives 30 m to `far` at once (r2 is 36 m off) and works it when it arrives, after about
  // 32 s.
  const auto id = client_->schedule(job("far", 30, 0, 3, 100, 2));
  const auto committed = client_->outcome(id);
  ASSERT_EQ(committed.outcome(), SWARM_COMMITTED) << committed.reason();
  ASSERT_EQ(committed.jobs()[0].robot(), "r1");
  const SwarmPlacedJob far = committed.jobs()[0];

  // Killed while r1 drives.
  auto& r1 = client_->state("r1");
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < until && !(r1.latest() && r1.latest()->x() > 2)) {
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(r1.latest() && r1.latest()->x() > 2) << "r1 does not drive to its job";
  const auto killed_at = wall_now();
  restart_coordinator();
  const auto s = client_->status(
      [&](const SwarmStatus& x) {
        return x.now_ns() > killed_at && in_planning(x, "r1") && in_planning(x, "r2");
      },
      "r1 and r2 in the new coordinator's planning");
  ASSERT_GT(s.now_ns(), killed_at);
  ASSERT_LT(s.now_ns(), far.start_ns() - 10'000'000'000) << "the restart took too long to test";

  // The new coordinator shows the job on r1 as its predecessor committed it.
  const SwarmPlacedJob* shown = find_job(s, "far");
  ASSERT_NE(shown, nullptr) << "the new coordinator does not know r1's committed job";
  EXPECT_EQ(shown->robot(), "r1");
  EXPECT_NEAR(shown->x(), far.x(), 1e-9);
  EXPECT_NEAR(shown->y(), far.y(), 1e-9);
  EXPECT_NEAR(static_cast<double>(shown->start_ns()), static_cast<double>(far.start_ns()), 1e3);
  EXPECT_NEAR(shown->duration_s(), far.duration_s(), 1e-6);
  EXPECT_EQ(shown->earliest_start_ns(), far.earliest_start_ns());
  EXPECT_EQ(shown->latest_finish_ns(), far.latest_finish_ns());

  // A job near the end of r1's way, which r1 can do only after `far`, goes to r1, planned from
  // where r1 will be then: it takes it at once. (Planned from where r1 stood at the restart, it
  // would start where r1 is not, be refused, and go to r2.)
  const auto on_way = client_->schedule(job("on_way", 22, 0, 3, 80, 2));
  const auto second = client_->outcome(on_way);
  ASSERT_EQ(second.outcome(), SWARM_COMMITTED) << second.reason();
  EXPECT_EQ(second.jobs()[0].robot(), "r1");
  const auto replies = client_->replies(on_way);
  ASSERT_EQ(replies.size(), 2u) << "planned once, committed";
  EXPECT_EQ(replies[0].outcome(), SWARM_PLANNED);
  EXPECT_EQ(replies[0].jobs()[0].robot(), "r1");

  // Every committed path keeps clear of the others from now on.
  const auto plan = client_->plan(
      [&](const SwarmPlan& p) {
        return p.now_ns() > killed_at &&
               std::any_of(p.jobs().begin(), p.jobs().end(),
                           [](const SwarmPlacedJob& j) { return j.id() == "on_way"; });
      },
      "the new coordinator's plan with on_way");
  ASSERT_EQ(plan.paths().size(), 2u);
  const auto& a = plan.paths()[0];
  const auto& b = plan.paths()[1];
  for (Stamp t = plan.now_ns(); t < second.jobs()[0].start_ns() + 10'000'000'000; t += 50'000'000) {
    const auto [ax, ay] = at(a, t);
    const auto [bx, by] = at(b, t);
    ASSERT_GE(std::hypot(ax - bx, ay - by), a.radius() + b.radius())
        << a.robot() << " and " << b.robot() << " at " << t;
  }

  // r1 works both jobs at their place within their window.
  for (const auto& [name, x] : {std::pair{"far", 30.0}, {"on_way", 22.0}}) {
    const auto w = client_->working("r1", name, 60s);
    ASSERT_TRUE(w) << "r1 never worked " << name;
    EXPECT_NEAR(w->x(), x, 0.1 + 1e-9) << name;
    EXPECT_NEAR(w->y(), 0, 0.1 + 1e-9) << name;
    const auto& placed = std::string(name) == "far" ? far : second.jobs()[0];
    EXPECT_GE(w->header().stamps()[0], static_cast<std::uint64_t>(placed.earliest_start_ns()));
    EXPECT_LE(w->header().stamps()[0], static_cast<std::uint64_t>(placed.latest_finish_ns()));
  }
}

}  // namespace
}  // namespace oscar
