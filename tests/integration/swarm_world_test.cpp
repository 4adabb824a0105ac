// A world that changes (docs/swarm.md, "A world that changes") on a booted system: an obstacle
// added across a robot's way is driven around and the job still done in its window, a moving one
// added at run time is let pass, one a robot meets before the frozen horizon is refused, removed
// obstacles are gone; a forklift going round a loop in Unix time (the system file's) is avoided;
// `oscar swarm world` says the same.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/swarm_types.hpp"
#include "oscar/time.hpp"
#include "process.hpp"  // tests/common
#include "swarm_client.hpp"

namespace oscar {
namespace {

using namespace std::chrono_literals;
using test::job;
using ::testing::HasSubstr;

// r1 and r2 at the west end of their lanes (y = 0 and y = 20); r3 west of the forklift's beat,
// which crosses y = 40 at x = 50 (a 1 m box between y = 35 and 45, every 20 s of Unix time).
constexpr const char* kSystem = R"(
system: swarm_world
modules:
  - name: robots
    mode: { continuous: 50ms }
    kernels:
      - { type: robot_sim, name: r1, params: { start_x: 0, start_y: 0, max_speed: 2 } }
      - { type: robot_sim, name: r2, params: { start_x: 0, start_y: 20, max_speed: 2 },
          mode: { single_step: { trigger: module } } }
      - { type: robot_sim, name: r3, params: { start_x: 40, start_y: 40, max_speed: 2 },
          mode: { single_step: { trigger: module } } }
  - name: monitor
    mode: { continuous: 50ms }
    kernels:
      - { type: safety_monitor, name: safety,
          inputs: { r1: r1/state, r2: r2/state, r3: r3/state },
          params: { moving_obstacles: '[ {shape: [[-0.5,-0.5],[0.5,-0.5],[0.5,0.5],[-0.5,0.5]], loop: [[50,35,0],[50,45,10],[50,35,20]]} ]' } }
coordinator:
  swarm:
    world:
      dynamic:
        - { name: forklift, shape: [[-0.5,-0.5],[0.5,-0.5],[0.5,0.5],[-0.5,0.5]],
            loop: [[50,35,0],[50,45,10],[50,35,20]] }
    frozen_horizon_ms: 1500
    ack_timeout_ms: 500
)";

constexpr double kRadius = 0.25;  // robot_sim's default

SwarmObstacle box(const std::string& name, double x0, double y0, double x1, double y1) {
  SwarmObstacle o;
  o.name(name);
  o.shape().x({x0, x1, x1, x0});
  o.shape().y({y0, y0, y1, y1});
  return o;
}

// How far p reaches into the box [x0, x1] × [y0, y1] grown by r (> 0: inside).
double depth_in(double px, double py, double x0, double y0, double x1, double y1, double r) {
  return std::min({px - (x0 - r), (x1 + r) - px, py - (y0 - r), (y1 + r) - py});
}

class SwarmWorld : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    system_ = new test::BootedSystem("swarm_world", kSystem);
    system_->running();
    client_ = new test::SwarmClient(system_->participant(), "swarm_world_test");
    violations_ = system_->watch<SafetyViolation>("safety/violations").release();
    client_->status([](const SwarmStatus& s) { return s.robots().size() == 3; }, "3 robots");
  }
  static void TearDownTestSuite() {
    delete violations_;
    delete client_;
    delete system_;
  }
  void TearDown() override {
    std::this_thread::sleep_for(300ms);
    for (const auto& v : violations_->take()) {
      ADD_FAILURE() << "safety violation " << v.kind() << ": " << v.detail();
    }
  }

  static SwarmReply change(SwarmRequest r) { return client_->outcome(client_->submit(r)); }
  static SwarmReply add(const SwarmObstacle& o) {
    SwarmRequest r;
    r.kind(SWARM_ADD_OBSTACLES);
    r.obstacles().push_back(o);
    return change(r);
  }
  static SwarmReply remove(const std::string& name) {
    SwarmRequest r;
    r.kind(SWARM_REMOVE_OBSTACLES);
    r.obstacle_names().push_back(name);
    return change(r);
  }
  // Waits until the status lists the obstacle `name` (or, with listed false, does not).
  static void expect_listed(const std::string& name, bool listed = true) {
    client_->status(
        [&](const SwarmStatus& s) {
          return (std::find(s.obstacles().begin(), s.obstacles().end(), name) !=
                  s.obstacles().end()) == listed;
        },
        listed ? "the obstacle" : "the obstacle gone");
  }
  static RobotState state_of(const std::string& robot) {
    auto& feed = client_->state(robot);
    for (int i = 0; i < 500 && !feed.latest(); ++i) std::this_thread::sleep_for(20ms);
    if (!feed.latest()) ADD_FAILURE() << robot << " sent no state";
    return feed.latest().value_or(RobotState{});
  }

  // Follows `robot` until it works `job`: the deepest it reached into the grown box on the way.
  static double deepest_until_working(const std::string& robot, const std::string& job_id,
                                      const std::function<double(const RobotState&)>& depth) {
    auto& feed = client_->state(robot);
    double deepest = -1e9;
    const auto until = std::chrono::steady_clock::now() + 60s;
    while (std::chrono::steady_clock::now() < until) {
      if (auto s = feed.latest()) {
        deepest = std::max(deepest, depth(*s));
        if (s->job().id() == job_id) return deepest;
      }
      std::this_thread::sleep_for(20ms);
    }
    ADD_FAILURE() << robot << " never worked " << job_id;
    return deepest;
  }

  static test::BootedSystem* system_;
  static test::SwarmClient* client_;
  static testing::CueWatch<SafetyViolation>* violations_;
};

test::BootedSystem* SwarmWorld::system_ = nullptr;
test::SwarmClient* SwarmWorld::client_ = nullptr;
testing::CueWatch<SafetyViolation>* SwarmWorld::violations_ = nullptr;

TEST_F(SwarmWorld, TheSystemFilesObstaclesAreTheWorld) { expect_listed("forklift"); }

// r1 drives east along y = 0 to a job at (24, 0); a wall across y = 0 at x = 12 comes while it
// drives. It goes round and still works the job in its window.
TEST_F(SwarmWorld, AnObstacleAddedAcrossARobotsWayIsDrivenAroundAndTheJobStillDone) {
  const auto placed = client_->outcome(client_->schedule(job("east", 24, 0, 18, 60, 2)));
  ASSERT_EQ(placed.outcome(), SWARM_COMMITTED) << placed.reason();
  ASSERT_EQ(placed.jobs()[0].robot(), "r1");
  const auto r = add(box("wall", 11.5, -3, 12.5, 3));
  ASSERT_EQ(r.outcome(), SWARM_COMMITTED) << r.reason();
  EXPECT_NE(r.transaction(), 0u) << "r1 had to be planned again";
  expect_listed("wall");
  const double deepest = deepest_until_working("r1", "east", [](const RobotState& s) {
    return depth_in(s.x(), s.y(), 11.5, -3, 12.5, 3, kRadius);
  });
  EXPECT_LE(deepest, 1e-3) << "r1 drove into the wall";
  const auto working = client_->working("r1", "east", 1s);
  ASSERT_TRUE(working);
  EXPECT_GE(working->header().stamps()[0], placed.jobs()[0].earliest_start_ns());
  ASSERT_EQ(remove("wall").outcome(), SWARM_COMMITTED);
  expect_listed("wall", false);
}

// A cart creeping across r2's lane at x = -12 from 3 s to 23 s from now, while r2 drives west
// along it to a job at (-24, 20): r2 cannot pass before the cart has, so it is planned again.
TEST_F(SwarmWorld, AMovingObstacleAddedAtRunTimeIsLetPass) {
  const auto placed = client_->outcome(client_->schedule(job("lane2", -24, 20, 18, 90, 2)));
  ASSERT_EQ(placed.outcome(), SWARM_COMMITTED) << placed.reason();
  ASSERT_EQ(placed.jobs()[0].robot(), "r2");
  auto cart = box("cart", -1, -1, 1, 1);
  const auto now = wall_now();
  for (const auto& [y, t] : {std::pair{19.5, 3.0}, {20.5, 23.0}}) {
    SwarmWaypoint w;
    w.x(-12);
    w.y(y);
    w.t_ns(now + static_cast<Stamp>(t * 1e9));
    cart.path().push_back(w);
  }
  const auto r = add(cart);
  ASSERT_EQ(r.outcome(), SWARM_COMMITTED) << r.reason();
  EXPECT_NE(r.transaction(), 0u) << "r2 had to be planned again";
  const double deepest = deepest_until_working("r2", "lane2", [&](const RobotState& s) {
    const double t = static_cast<double>(s.header().stamps()[0] - now) * 1e-9;
    if (t < 3 || t > 23) return -1e9;  // it exists only meanwhile
    const double cy = 19.5 + (t - 3) / 20;
    return depth_in(s.x(), s.y(), -13, cy - 1, -11, cy + 1, kRadius);
  });
  EXPECT_LE(deepest, 0.05) << "r2 met the cart";  // states are 50 ms apart at 2 m/s
  ASSERT_EQ(remove("cart").outcome(), SWARM_COMMITTED);
}

TEST_F(SwarmWorld, AnObstacleOnARobotBeforeTheFrozenHorizonIsRefused) {
  const auto s = state_of("r3");
  const auto r = add(box("on_r3", s.x() - 1, s.y() - 1, s.x() + 1, s.y() + 1));
  EXPECT_EQ(r.outcome(), SWARM_REFUSED);
  EXPECT_THAT(r.reason(), HasSubstr("node 'r3' runs into the changed world"));
  EXPECT_THAT(r.reason(), HasSubstr("before the frozen horizon"));
  std::this_thread::sleep_for(1200ms);  // a status or two later
  expect_listed("on_r3", false);
}

TEST_F(SwarmWorld, BadChangesAreRefusedWithTheReason) {
  auto tie = box("tie", 60, 60, 61, 61);
  tie.shape().y({60, 61, 60, 61});
  EXPECT_THAT(add(tie).reason(), HasSubstr("self-intersecting"));
  EXPECT_THAT(add(box("forklift", 60, 60, 61, 61)).reason(),
              HasSubstr("obstacle 'forklift': the world has one of that name already"));
  const auto r = remove("nothing");
  EXPECT_EQ(r.outcome(), SWARM_REFUSED);
  EXPECT_THAT(r.reason(), HasSubstr("the world has no obstacle 'nothing'"));
}

// r3 at (40, 40) works a job at (60, 40): on the way it crosses the forklift's beat at x = 50,
// which the system file's loop has in Unix time, as the monitor has it.
TEST_F(SwarmWorld, ARobotCrossesTheForkliftsBeatWhenTheForkliftIsElsewhere) {
  const auto placed = client_->outcome(client_->schedule(job("beyond", 60, 40, 5, 90, 2)));
  ASSERT_EQ(placed.outcome(), SWARM_COMMITTED) << placed.reason();
  ASSERT_EQ(placed.jobs()[0].robot(), "r3");
  const double deepest = deepest_until_working("r3", "beyond", [](const RobotState& s) {
    const double period = 20;
    const double phase = std::fmod(static_cast<double>(s.header().stamps()[0]) * 1e-9, period);
    const double cy = 35 + (phase < 10 ? phase : 20 - phase);
    return depth_in(s.x(), s.y(), 49.5, cy - 0.5, 50.5, cy + 0.5, kRadius);
  });
  EXPECT_LE(deepest, 0.05) << "r3 met the forklift";
}

TEST_F(SwarmWorld, TheCommandLineAddsAndRemovesObstacles) {
  auto run = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {test::bin("oscar-swarm"), "world"});
    // Generous under sanitizers on a loaded machine: the tool's own limits (matching, then the
    // outcome) are what the test checks, never the test's patience.
    args.insert(args.end(), {"-d", std::to_string(system_->domain()), "--timeout", "30"});
    test::Process p(args, test::temp_path("swarm_world_cli.log"));
    const int code = p.wait(120s).value_or(-1);
    return std::pair{code, p.output()};
  };
  const auto [added, added_text] =
      run({"add", "crate", "--polygon", "[[70,0],[71,0],[71,1],[70,1]]"});
  EXPECT_EQ(added, 0) << added_text;
  expect_listed("crate");
  const auto [bad, bad_text] = run({"add", "crate", "--polygon", "[[80,0],[81,0],[81,1]]"});
  EXPECT_EQ(bad, 1) << bad_text;
  EXPECT_THAT(bad_text, HasSubstr("refused: obstacle 'crate': the world has one of that name"));
  const auto [wrong, wrong_text] = run({"add", "x", "--polygon", "[[80,0],[81]]"});
  EXPECT_EQ(wrong, 2) << wrong_text;
  EXPECT_THAT(wrong_text, HasSubstr("--polygon: point 2 is not [x, y] of finite numbers"));
  const auto [removed, removed_text] = run({"remove", "crate"});
  EXPECT_EQ(removed, 0) << removed_text;
  expect_listed("crate", false);
}

}  // namespace
}  // namespace oscar
