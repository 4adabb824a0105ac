// The live swarm (docs/swarm.md, "The live swarm") on a booted system: jobs submitted over DDS
// are placed by the coordinator, proposed to robot_sim pilots, committed on their ACKs and done
// by the robots at their place within their window; a NAK or a silent robot aborts that part and
// the job goes elsewhere; a robot that breaks down gives its jobs to others, a job set's within
// the set or, if that cannot be, the whole set is aborted; bad requests are refused with the
// reason.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "oscar/coordinator/cue_feed.hpp"
#include "oscar/swarm_types.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "process.hpp"  // tests/common
#include "swarm_client.hpp"

namespace oscar {
namespace {

using namespace std::chrono_literals;
using test::job;
using ::testing::Contains;
using ::testing::HasSubstr;
using Client = test::SwarmClient;

// Nine robots: r1 and r2 do as told; rn refuses everything; rs (a module of its own) answers
// after the coordinator stopped waiting; rb (a module of its own) breaks down when told to. Out
// of reach of the other tests' jobs, for job sets of robots that break down: rb2 with r3 next to
// it, rb3 with r4 29 m away.
constexpr const char* kSystem = R"(
system: swarm_live
modules:
  - name: robots
    mode: { continuous: 50ms }
    kernels:
      - { type: robot_sim, name: r1, params: { start_x: 0, start_y: 0, max_speed: 2 } }
      - { type: robot_sim, name: r2, params: { start_x: 0, start_y: 20, max_speed: 2 },
          mode: { single_step: { trigger: module } } }
      - { type: robot_sim, name: rn, params: { start_x: 20, start_y: 0, max_speed: 2, nak_probability: 1 },
          mode: { single_step: { trigger: module } } }
      - { type: robot_sim, name: r3, params: { start_x: 304, start_y: 0, max_speed: 2 },
          mode: { single_step: { trigger: module } } }
      - { type: robot_sim, name: r4, params: { start_x: 340, start_y: 30, max_speed: 2 },
          mode: { single_step: { trigger: module } } }
  - name: slow
    mode: { continuous: 50ms }
    kernels:
      - { type: robot_sim, name: rs, params: { start_x: 20, start_y: 20, max_speed: 2, ack_delay_ms: 900 } }
  - name: fragile
    mode: { continuous: 50ms }
    kernels:
      - { type: robot_sim, name: rb, params: { start_x: 40, start_y: 0, max_speed: 2 } }
      - { type: robot_sim, name: rb2, params: { start_x: 300, start_y: 0, max_speed: 2 },
          mode: { single_step: { trigger: module } } }
      - { type: robot_sim, name: rb3, params: { start_x: 340, start_y: 0, max_speed: 2 },
          mode: { single_step: { trigger: module } } }
  - name: monitor
    mode: { continuous: 50ms }
    kernels:
      - { type: safety_monitor, name: safety,
          inputs: { r1: r1/state, r2: r2/state, rn: rn/state, rs: rs/state, rb: rb/state,
                    r3: r3/state, r4: r4/state, rb2: rb2/state, rb3: rb3/state } }
coordinator:
  swarm:
    frozen_horizon_ms: 1500
    ack_timeout_ms: 500
    replan_attempts: 3
)";

// A dependent set: job `b` waits for job `a`.
SwarmRequest a_then_b(const SwarmJobSpec& a, const SwarmJobSpec& b) {
  SwarmRequest r;
  r.kind(SWARM_DEPENDENT);
  r.jobs({a, b});
  SwarmDependency d;
  d.job(b.id());
  d.after({a.id()});
  r.depends().push_back(d);
  return r;
}

Stamp end_ns(const SwarmPlacedJob& j) {
  return j.start_ns() + static_cast<Stamp>(j.duration_s() * 1e9);
}

class LiveSwarm : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    system_ = new test::BootedSystem("swarm_live", kSystem);
    system_->running();
    client_ = new Client(system_->participant(), "swarm_live_test");
    violations_ = system_->watch<SafetyViolation>("safety/violations").release();
  }
  static void TearDownTestSuite() {
    delete violations_;
    delete client_;
    delete system_;
  }

  // After each test: nothing it did brought robots too close, into an obstacle or off their
  // jobs, by the safety monitor's own account.
  void TearDown() override {
    std::this_thread::sleep_for(300ms);  // the last states reach the monitor and its cues us
    for (const auto& v : violations_->take()) {
      ADD_FAILURE() << "safety violation " << v.kind() << ": " << v.detail();
    }
  }

  // Waits until the coordinator plans with `robot`: each test boots the system anew, and on a
  // slow machine a robot's module may still be coming up when the others are in planning.
  static void in_planning(const std::string& robot) {
    client_->status(
        [&](const SwarmStatus& s) {
          return std::find(s.robots().begin(), s.robots().end(), robot) != s.robots().end();
        },
        (robot + " in planning").c_str());
  }
  // The tests choose their jobs' places by which robot is nearest, so all nine must be there.
  static void all_in_planning() {
    client_->status([](const SwarmStatus& x) { return x.robots().size() == 9; },
                    "nine robots in planning");
  }

  // Waits until the robot standing at (x, y) is in planning and the coordinator reaches it: its
  // first command to a module may time out while the module's command channel is discovered
  // (ConfigClient opens it on first use), and the job would go elsewhere. So a tiny job where
  // the robot stands, due so soon that no other robot gets there, until it is committed.
  static void ready(const std::string& robot, double x, double y) {
    in_planning(robot);
    std::string why;
    for (int attempt = 0; attempt < 5; ++attempt) {
      const auto id = robot + "_ready_" + std::to_string(attempt);
      const auto r = client_->outcome(client_->schedule(job(id, x, y, 1.6, 2.4, 0.2)));
      if (r.outcome() == SWARM_COMMITTED) return;
      why = r.reason();
    }
    ADD_FAILURE() << "the coordinator never reached " << robot << ": " << why;
  }

  // The committed jobs named `ids`, from the first status that lists them all.
  static std::vector<SwarmPlacedJob> jobs_named(const std::vector<std::string>& ids) {
    auto named = [&](const SwarmStatus& s) {
      std::vector<SwarmPlacedJob> out;
      for (const auto& j : s.jobs()) {
        if (std::find(ids.begin(), ids.end(), j.id()) != ids.end()) out.push_back(j);
      }
      return out;
    };
    return named(client_->status(
        [&](const SwarmStatus& s) { return named(s).size() >= ids.size(); }, "the jobs"));
  }

  static test::BootedSystem* system_;
  static Client* client_;
  static testing::CueWatch<SafetyViolation>* violations_;
};

test::BootedSystem* LiveSwarm::system_ = nullptr;
Client* LiveSwarm::client_ = nullptr;
testing::CueWatch<SafetyViolation>* LiveSwarm::violations_ = nullptr;

TEST_F(LiveSwarm, AllRobotsJoinPlanning) {
  const auto s = client_->status([](const SwarmStatus& x) { return x.robots().size() == 9; },
                                 "nine robots in planning");
  EXPECT_EQ(s.robots().size(), 9u);
}

TEST_F(LiveSwarm, AJobSubmittedOverDdsIsDoneByTheNearestRobotAtItsPlaceInItsWindow) {
  all_in_planning();
  const auto id = client_->schedule(job("near_r1", 2, 1, 3, 30, 2));
  const auto r = client_->outcome(id);
  ASSERT_EQ(r.outcome(), SWARM_COMMITTED) << r.reason();
  ASSERT_EQ(r.jobs().size(), 1u);
  EXPECT_EQ(r.jobs()[0].robot(), "r1");
  const auto s = client_->working("r1", "near_r1", 40s);
  ASSERT_TRUE(s) << "r1 never worked the job";
  EXPECT_NEAR(s->x(), r.jobs()[0].x(), 0.01);
  EXPECT_NEAR(s->y(), r.jobs()[0].y(), 0.01);
  EXPECT_GE(s->header().stamps()[0], r.jobs()[0].earliest_start_ns());
  EXPECT_LE(s->header().stamps()[0], r.jobs()[0].latest_finish_ns());
  EXPECT_NEAR(s->x(), 2, 0.1 + 1e-9);
  EXPECT_NEAR(s->y(), 1, 0.1 + 1e-9);
}

TEST_F(LiveSwarm, ANakAbortsThatRobotsPartAndTheJobIsPlacedElsewhere) {
  all_in_planning();
  const auto before = client_->status([](const SwarmStatus&) { return true; }, "a status");
  const auto id = client_->schedule(job("near_rn", 19, 1, 3, 60, 2));  // rn is nearest
  const auto r = client_->outcome(id);
  ASSERT_EQ(r.outcome(), SWARM_COMMITTED) << r.reason();
  EXPECT_NE(r.jobs()[0].robot(), "rn");
  const auto planned = client_->replies(id);
  ASSERT_GE(planned.size(), 3u);  // planned on rn, planned again elsewhere, committed
  EXPECT_EQ(planned[0].outcome(), SWARM_PLANNED);
  EXPECT_EQ(planned[0].jobs()[0].robot(), "rn");
  const auto after = client_->status([&](const SwarmStatus& s) { return s.naks() > before.naks(); },
                                     "the NAK counted");
  EXPECT_GT(after.replans(), before.replans());
}

TEST_F(LiveSwarm, ASilentRobotTimesOutAndTheJobIsPlacedElsewhere) {
  all_in_planning();
  const auto before = client_->status([](const SwarmStatus&) { return true; }, "a status");
  const auto id = client_->schedule(job("near_rs", 19, 19, 4, 60, 2));  // rs is nearest
  const auto r = client_->outcome(id);
  ASSERT_EQ(r.outcome(), SWARM_COMMITTED) << r.reason();
  EXPECT_NE(r.jobs()[0].robot(), "rs");
  const auto planned = client_->replies(id);
  ASSERT_GE(planned.size(), 2u);
  EXPECT_EQ(planned[0].jobs()[0].robot(), "rs");
  client_->status([&](const SwarmStatus& s) { return s.timeouts() > before.timeouts(); },
                  "the timeout counted");
}

TEST_F(LiveSwarm, BadJobSpecificationsAreRefusedWithTheReason) {
  all_in_planning();  // its last job is a good one, planned and proposed like any other
  auto too_short = job("short", 5, 5, 3, 4, 2);  // a 1 s window for 2 s of work
  const auto a = client_->outcome(client_->schedule(too_short));
  EXPECT_EQ(a.outcome(), SWARM_REFUSED);
  EXPECT_NE(a.reason().find("window"), std::string::npos) << a.reason();
  auto bowtie = job("bowtie", 5, 5, 3, 30, 2);
  bowtie.area().x({0, 1, 0, 1});
  bowtie.area().y({0, 1, 1, 0});
  const auto b = client_->outcome(client_->schedule(bowtie));
  EXPECT_EQ(b.outcome(), SWARM_REFUSED);
  EXPECT_NE(b.reason().find("job 'bowtie' area"), std::string::npos) << b.reason();
  SwarmRequest nothing;
  nothing.kind(SWARM_SCHEDULE);
  const auto c = client_->outcome(client_->submit(nothing));
  EXPECT_EQ(c.outcome(), SWARM_REFUSED);
  EXPECT_NE(c.reason().find("needs its job"), std::string::npos) << c.reason();
  const auto d = client_->outcome(client_->schedule(job("near_r1", 2, 1, 3, 30, 2)));
  if (d.outcome() != SWARM_COMMITTED) {  // the first test's job may still be on r1's schedule
    EXPECT_NE(d.reason().find("already scheduled"), std::string::npos) << d.reason();
  }
}

TEST_F(LiveSwarm, ABrokenDownRobotsJobsGoToOthers) {
  all_in_planning();
  // rb is nearest; it breaks down before the job's window.
  const auto id = client_->schedule(job("after_breakdown", 39, 1, 20, 90, 2));
  const auto first = client_->outcome(id);
  ASSERT_EQ(first.outcome(), SWARM_COMMITTED) << first.reason();
  ASSERT_EQ(first.jobs()[0].robot(), "rb");
  ASSERT_TRUE(system_->configure("fragile", CMD_SET_PARAM, {"rb", "breakdown_after_s", "0"}).ok());
  const auto lost = client_->status(
      [](const SwarmStatus& s) {
        return std::find(s.lost_robots().begin(), s.lost_robots().end(), "rb") !=
               s.lost_robots().end();
      },
      "rb lost");
  const auto again = client_->outcome(id, 1);
  ASSERT_EQ(again.outcome(), SWARM_COMMITTED) << again.reason();
  EXPECT_NE(again.jobs()[0].robot(), "rb");
}

TEST_F(LiveSwarm, ADependentSetStaysWholeWhenOneOfItsRobotsRefuses) {
  all_in_planning();
  // A is nearest rn (which refuses), B nearest r2: the first plan asks both, rn's NAK aborts the
  // whole set, and the set is planned again without rn.
  const auto id =
      client_->submit(a_then_b(job("set_a", 21, -1, 3, 60, 2), job("set_b", 1, 21, 3, 60, 2)));
  const auto outcome = client_->outcome(id);
  ASSERT_EQ(outcome.outcome(), SWARM_COMMITTED) << outcome.reason();
  const auto replies = client_->replies(id);
  ASSERT_GE(replies.size(), 3u);
  EXPECT_EQ(replies[0].outcome(), SWARM_PLANNED);
  EXPECT_NE(replies[0].transaction(), outcome.transaction());
  const auto placed = jobs_named({"set_a", "set_b"});
  ASSERT_EQ(placed.size(), 2u) << "the set is placed once, whole";
  EXPECT_NE(placed[0].id(), placed[1].id());
  for (const auto& j : placed) EXPECT_NE(j.robot(), "rn") << j.id();
  const auto& a = placed[0].id() == "set_a" ? placed[0] : placed[1];
  const auto& b = placed[0].id() == "set_a" ? placed[1] : placed[0];
  EXPECT_GE(b.start_ns(), end_ns(a));
}

// True if two placed jobs are at least `clearance` apart or do not overlap in time.
bool clear_of(const SwarmPlacedJob& a, const SwarmPlacedJob& b, double clearance) {
  return std::hypot(a.x() - b.x(), a.y() - b.y()) >= clearance || end_ns(a) <= b.start_ns() ||
         end_ns(b) <= a.start_ns();
}

TEST_F(LiveSwarm, ConcurrentSubmissionsSeeEachOthersOpenTransactions) {
  all_in_planning();
  // Two requesters want the same 2 m square at once. The first plan goes to rs, which answers
  // only after the coordinator stopped waiting, so that transaction is open while the second
  // request is planned: the second must keep clear of it (and of where rs stands meanwhile).
  const auto first = client_->schedule(job("spot_1", 21, 21, 4, 40, 3));
  auto area = job("spot_2", 21, 21, 4, 40, 3);
  area.area().x({20, 22, 22, 20});
  area.area().y({20, 20, 22, 22});
  const auto second = client_->schedule(area);
  const auto r1 = client_->outcome(first);
  const auto r2 = client_->outcome(second);
  ASSERT_EQ(r1.outcome(), SWARM_COMMITTED) << r1.reason();
  const auto planned_first = client_->replies(first).front();
  ASSERT_EQ(planned_first.outcome(), SWARM_PLANNED);
  ASSERT_EQ(planned_first.jobs()[0].robot(), "rs");
  ASSERT_EQ(r2.outcome(), SWARM_COMMITTED) << r2.reason();
  const auto& b = r2.jobs()[0];
  const double clearance = 0.6;  // two robots' radii
  EXPECT_TRUE(clear_of(planned_first.jobs()[0], b, clearance))
      << "spot_2 was placed onto spot_1's open alternative";
  EXPECT_TRUE(clear_of(r1.jobs()[0], b, clearance)) << "spot_1 and spot_2 collide";
  EXPECT_GE(std::hypot(b.x() - 20, b.y() - 20), clearance) << "spot_2 lies where rs stands";
}

// Runs `oscar swarm ARGS...`: its exit code and its output (standard output and error).
struct ToolRun {
  int exit_code = -1;
  std::string output;
};
ToolRun run_swarm_tool(std::vector<std::string> args) {
  const auto log =
      (std::filesystem::temp_directory_path() / fmt::format("swarm_tool_{}.log", getpid()))
          .string();
  args.insert(args.begin(), test::bin("oscar-swarm"));
  test::Process p(args, log);
  ToolRun run;
  run.exit_code = p.wait(30s).value_or(-1);
  run.output = p.output();
  std::filesystem::remove(log);
  return run;
}

// Runs `oscar swarm snapshot` with `args`; its exit code, its output and the picture it drew.
struct Snapshot : ToolRun {
  std::string svg;
};
Snapshot snapshot(std::vector<std::string> args) {
  const auto file =
      (std::filesystem::temp_directory_path() / fmt::format("swarm_snapshot_{}.svg", getpid()))
          .string();
  args.insert(args.begin(), {"snapshot", "-o", file});
  Snapshot s{run_swarm_tool(args), {}};
  std::ifstream in(file);
  s.svg.assign(std::istreambuf_iterator<char>(in), {});
  std::filesystem::remove(file);
  return s;
}

// `oscar swarm status --json`: the robots in planning, the job committed and still to do, the
// counts.
TEST_F(LiveSwarm, TheStatusListsTheRobotsInPlanningAndTheJobsAhead) {
  all_in_planning();
  const auto id = client_->schedule(job("listed", 6, 3, 20, 60, 2));
  const auto r = client_->outcome(id);
  ASSERT_EQ(r.outcome(), SWARM_COMMITTED) << r.reason();
  // The status is published every second and after each change: wait for the one with the job.
  client_->status(
      [](const SwarmStatus& s) {
        return std::any_of(s.jobs().begin(), s.jobs().end(),
                           [](const auto& j) { return j.id() == "listed"; });
      },
      "the job listed");
  const auto run =
      run_swarm_tool({"status", "--json", "-d", std::to_string(system_->domain()), "--timeout",
                      "10"});  // (a loaded host under a sanitizer may need more than 3 s)
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto doc = nlohmann::json::parse(run.output.substr(run.output.find('{')));
  const auto robots = doc.at("robots").get<std::vector<std::string>>();
  for (const std::string robot : {"r1", "r2", "rn", "rs"}) {
    EXPECT_THAT(robots, Contains(robot)) << run.output;
  }
  EXPECT_GE(doc.at("jobs_submitted").get<int>(), 1);
  EXPECT_GE(doc.at("jobs_committed").get<int>(), 1);
  bool listed = false;
  for (const auto& j : doc.at("jobs")) {
    if (j.at("id") != "listed") continue;
    listed = true;
    EXPECT_EQ(j.at("robot"), r.jobs()[0].robot());
    EXPECT_GT(j.at("start_s").get<double>(), 0) << "its window opens 20 s from the submission";
  }
  EXPECT_TRUE(listed) << run.output;
}

// The picture of the running swarm: the robots where they are, labelled, the committed path of
// a robot on its way to a job, and the job with its start from now.
TEST_F(LiveSwarm, TheSnapshotDrawsTheRobotsTheirCommittedPathsAndJobs) {
  all_in_planning();
  const auto id = client_->schedule(job("drawn", 6, 3, 20, 60, 2));
  const auto r = client_->outcome(id);
  ASSERT_EQ(r.outcome(), SWARM_COMMITTED) << r.reason();
  ASSERT_EQ(r.jobs().size(), 1u);
  const auto robot = r.jobs()[0].robot();
  // The plan is published at most twice a second: the next one has the job.
  std::this_thread::sleep_for(700ms);
  // (A loaded host under a sanitizer may take more than the default 3 s to find the coordinator.)
  const auto s = snapshot({"-d", std::to_string(system_->domain()), "--timeout", "10"});
  ASSERT_EQ(s.exit_code, 0) << s.output;
  EXPECT_THAT(s.svg, HasSubstr(">drawn @+"));
  for (const std::string r_id : {"r1", "r2", "rn", "rs"}) {
    EXPECT_THAT(s.svg, HasSubstr(">" + r_id + "</text>")) << r_id << " is not in the picture";
  }
  // Each robot is a disc; the one with the job has a path of more than its place now.
  std::size_t discs = 0, paths = 0;
  for (std::size_t at = 0; (at = s.svg.find("<circle", at)) != std::string::npos; ++at) ++discs;
  for (std::size_t at = 0; (at = s.svg.find("<polyline points=\"", at)) != std::string::npos;
       ++at) {
    const auto end = s.svg.find('"', at + 18);
    const auto points = s.svg.substr(at + 18, end - at - 18);
    if (std::count(points.begin(), points.end(), ' ') >= 2) ++paths;  // two points or more
  }
  EXPECT_GE(discs, 5u + 1u) << "five robots and the job";
  EXPECT_GE(paths, 1u) << robot << "'s path to the job is missing";
}

// Without a coordinator that plans a swarm, the snapshot says so and draws nothing.
TEST(SwarmSnapshot, WithoutACoordinatorItSaysSoAndExits2) {
  testing::FreeDomain nobody;
  const auto s = snapshot({"-d", std::to_string(nobody.domain()), "--timeout", "0.5"});
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_THAT(s.output, HasSubstr("no coordinator published a swarm plan on domain"));
  EXPECT_TRUE(s.svg.empty());
}

// Without a coordinator, the status says so.
TEST(SwarmStatusCommand, WithoutACoordinatorItSaysSoAndExits2) {
  testing::FreeDomain nobody;
  const auto run =
      run_swarm_tool({"status", "-d", std::to_string(nobody.domain()), "--timeout", "0.5"});
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr(fmt::format(
                              "oscar swarm status: no coordinator published a swarm status on "
                              "domain {} within 0.5 s",
                              nobody.domain())));
}

// A coordinator that offers its topic but sends nothing (hung) is told apart from no
// coordinator, by both commands that read the coordinator.
TEST(SwarmSnapshot, ACoordinatorThatSendsNothingIsNamedAsSuch) {
  testing::FreeDomain domain;
  DdsParticipant participant(domain.domain(), "test:hung_coordinator");
  TopicWriter<SwarmPlan, SwarmPlanPubSubType> silent_plan(participant, topics::swarm_plan());
  TopicWriter<SwarmStatus, SwarmStatusPubSubType> silent_status(participant,
                                                                topics::swarm_status());
  const auto d = std::to_string(domain.domain());
  const auto s = snapshot({"-d", d, "--timeout", "1.5"});
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_THAT(s.output, HasSubstr(fmt::format("oscar swarm snapshot: the coordinator on domain {} "
                                              "offers a swarm plan but sent none within 3.0 s",
                                              domain.domain())));
  EXPECT_TRUE(s.svg.empty());
  const auto status = run_swarm_tool({"status", "-d", d, "--timeout", "1.5"});
  EXPECT_EQ(status.exit_code, 2);
  EXPECT_THAT(status.output,
              HasSubstr(fmt::format("oscar swarm status: the coordinator on domain {} offers a "
                                    "swarm status but sent none within 3.0 s",
                                    domain.domain())));
}

// The placed job named `id` of a reply.
const SwarmPlacedJob* placed_job(const SwarmReply& r, const std::string& id) {
  for (const auto& j : r.jobs()) {
    if (j.id() == id) return &j;
  }
  return nullptr;
}

TEST_F(LiveSwarm, ADependentSetKeepsItsOrderWhenOneOfItsRobotsBreaksDown) {
  ready("rb2", 300, 0);
  ready("r3", 304, 0);
  // order_a goes to rb2 next to it, order_b (which waits for it) to r3; rb2 breaks down before
  // order_a starts. Alone in its window order_a would go to r3 after order_b (the least detour);
  // within its set it must end before order_b starts: r3 does it first.
  const auto id = client_->submit(
      a_then_b(job("order_a", 301, 1, 8, 60, 2), job("order_b", 304, 1, 14, 60, 2)));
  const auto first = client_->outcome(id);
  ASSERT_EQ(first.outcome(), SWARM_COMMITTED) << first.reason();
  const auto* b = placed_job(first, "order_b");
  ASSERT_TRUE(placed_job(first, "order_a") && b);
  ASSERT_EQ(placed_job(first, "order_a")->robot(), "rb2");
  ASSERT_EQ(b->robot(), "r3");
  ASSERT_TRUE(system_->configure("fragile", CMD_SET_PARAM, {"rb2", "breakdown_after_s", "0"}).ok());
  const auto again = client_->outcome(id, 1);
  ASSERT_EQ(again.outcome(), SWARM_COMMITTED) << again.reason();
  ASSERT_EQ(again.jobs().size(), 1u);
  const auto& a = again.jobs()[0];
  EXPECT_EQ(a.id(), "order_a");
  EXPECT_EQ(a.robot(), "r3");
  EXPECT_LE(end_ns(a), b->start_ns()) << "order_a ends after order_b, which waits for it, starts";
  // It is still a member of its set: not unscheduled alone.
  SwarmRequest alone;
  alone.kind(SWARM_UNSCHEDULE);
  alone.job_id("order_a");
  const auto refused = client_->outcome(client_->submit(alone));
  EXPECT_EQ(refused.outcome(), SWARM_REFUSED);
  EXPECT_NE(refused.reason().find("belongs to the dependent set order_a, order_b"),
            std::string::npos)
      << refused.reason();
  // And r3 works them in that order.
  const auto doing_a = client_->working("r3", "order_a", 30s);
  ASSERT_TRUE(doing_a) << "r3 never worked order_a";
  EXPECT_LE(doing_a->header().stamps()[0], b->start_ns());
  const auto doing_b = client_->working("r3", "order_b", 30s);
  ASSERT_TRUE(doing_b) << "r3 never worked order_b";
  EXPECT_GE(doing_b->header().stamps()[0], end_ns(a));
}

TEST_F(LiveSwarm, ADependentSetThatCannotBeWholeAgainIsAbortedWhole) {
  ready("rb3", 340, 0);
  ready("r4", 340, 30);
  // whole_a goes to rb3 next to it, whole_b (which waits for it) to r4, 29 m away. rb3 breaks
  // down before whole_a starts, and no robot gets there in time to end it before whole_b starts:
  // the set is aborted, and whole_b leaves r4's schedule.
  const auto id = client_->submit(
      a_then_b(job("whole_a", 341, 1, 6, 60, 2), job("whole_b", 341, 29, 10, 60, 2)));
  const auto first = client_->outcome(id);
  ASSERT_EQ(first.outcome(), SWARM_COMMITTED) << first.reason();
  const auto* b = placed_job(first, "whole_b");
  ASSERT_TRUE(placed_job(first, "whole_a") && b);
  ASSERT_EQ(placed_job(first, "whole_a")->robot(), "rb3");
  ASSERT_EQ(b->robot(), "r4");
  const Stamp b_end = end_ns(*b);
  ASSERT_TRUE(system_->configure("fragile", CMD_SET_PARAM, {"rb3", "breakdown_after_s", "0"}).ok());
  const auto end = client_->outcome(id, 1);
  EXPECT_EQ(end.outcome(), SWARM_ABORTED);
  EXPECT_NE(end.reason().find("robot 'rb3' broke down and the dependent set whole_a, whole_b "
                              "cannot be whole again"),
            std::string::npos)
      << end.reason();
  EXPECT_NE(end.reason().find("members not started are unscheduled"), std::string::npos)
      << end.reason();
  const auto aborted_at = wall_now();
  client_->status(
      [&](const SwarmStatus& s) {
        return s.now_ns() > aborted_at &&
               std::none_of(s.jobs().begin(), s.jobs().end(), [](const SwarmPlacedJob& j) {
                 return j.id() == "whole_a" || j.id() == "whole_b";
               });
      },
      "no job of the set");
  // r4 does not work whole_b when it was due.
  const auto until_b_ended = std::chrono::seconds((b_end - wall_now()) / 1'000'000'000 + 1);
  EXPECT_FALSE(client_->working("r4", "whole_b", until_b_ended))
      << "r4 worked whole_b all the same";
}

}  // namespace
}  // namespace oscar
