#include "oscar/swarm/problem.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>
#include <vector>

#include "expect_error.hpp"
#include "oscar/swarm/problem_runner.hpp"

namespace oscar::swarm {
namespace {

const std::string kNodes = R"(
nodes:
  - { id: n1, radius: 0.1, max_speed: 0.5, start: [0, 0, 0] }
)";

void expect_error(const std::string& text, const std::string& part) {
  try {
    parse_problem(text, "p.yaml");
    FAIL() << "no exception; expected '" << part << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(Problem, RunsAndWritesTheDocumentedJson) {
  const auto p = parse_problem(kNodes + R"(
operations:
  - { op: schedule, job: { id: J1, area: [[4,2],[6,2],[6,4],[4,4]], earliest_start: 10, latest_finish: 60, duration: 10 } }
  - { op: commit }
)",
                               "p.yaml");
  ProblemRunner runner(p);
  runner.run();
  const auto doc = nlohmann::json::parse(runner.to_json());
  ASSERT_EQ(doc["operations"].size(), 2u);
  EXPECT_TRUE(doc["operations"][0]["ok"]);
  EXPECT_EQ(doc["operations"][0]["transaction"], 1);
  ASSERT_EQ(doc["jobs"].size(), 1u);
  EXPECT_EQ(doc["jobs"][0]["node"], "n1");
  EXPECT_DOUBLE_EQ(doc["jobs"][0]["x"].get<double>(), 5);
  EXPECT_GE(doc["nodes"][0]["trajectory"].size(), 3u);
  EXPECT_TRUE(doc["world"]["static"].is_array());
}

TEST(Problem, JsonInputWorksToo) {
  const auto p = parse_problem(
      R"({"nodes": [{"id": "n1", "radius": 0.1, "max_speed": 1, "start": [0, 0, 0]}],
          "operations": [{"op": "set_present", "t": 3}]})",
      "p.json");
  EXPECT_EQ(p.operations.size(), 1u);
}

TEST(Problem, SettingsSeedIsAnUnsignedInteger) {
  EXPECT_EQ(parse_problem(kNodes + "settings: { seed: 4294967295 }\n", "p.yaml").settings.seed,
            4294967295u);
  EXPECT_EQ(parse_problem(kNodes, "p.yaml").settings.seed, 1u);  // SchedulerSettings' default
  for (const auto* bad : {"-1", "4294967296", "2.5"}) {
    expect_error(kNodes + "settings: { seed: " + bad + " }\n",
                 std::string("p.yaml:4:19: settings.seed = ") + bad +
                     ": expected an integer from 0 to 4294967295");
  }
}

TEST(Problem, BadInputNamesFileLineAndRule) {
  expect_error(kNodes +
                   "operations:\n  - { op: schedule, job: { id: J, area: [[0,0],[1,0],[1,1]], "
                   "earliest_start: .nan, latest_finish: 60, duration: 10 } }\n",
               "p.yaml:5:");
  expect_error(kNodes +
                   "operations:\n  - { op: schedule, job: { id: J, area: [[0,0],[1,0],[1,1]], "
                   "earliest_start: .nan, latest_finish: 60, duration: 10 } }\n",
               "must be finite");
  expect_error(
      kNodes +
          "operations:\n  - { op: schedule, job: { id: J, area: [[0,0],[1,1],[1,0],[0,1]], "
          "earliest_start: 0, latest_finish: 60, duration: 10 } }\n",
      "self-intersecting");
  expect_error(kNodes +
                   "operations:\n  - { op: schedule, job: { id: J, area: [], "
                   "earliest_start: 0, latest_finish: 60, duration: 10 } }\n",
               "at least 3 vertices");
  expect_error(kNodes +
                   "operations:\n  - { op: schedule, job: { id: J, area: [[0,0],[1,0],[1,1]], "
                   "earliest_start: 0, latest_finish: 5, duration: 10 } }\n",
               "shorter than the duration");
  expect_error(kNodes + "operations:\n  - { op: unschedule, id: Q }\n",
               "p.yaml:5:5: unschedule: unknown job id 'Q'");
  expect_error(kNodes + "operations:\n  - { op: commit, node: n9 }\n", "unknown node id 'n9'");
  expect_error(
      kNodes + "operations:\n  - { op: set_present, t: 5 }\n  - { op: set_present, t: 4 }\n",
      "p.yaml:6:5: set_present: present time must not go backwards");
  expect_error(kNodes + R"(operations:
  - op: schedule_dependent
    jobs:
      - { id: A, area: [[0,0],[1,0],[1,1]], earliest_start: 0, latest_finish: 60, duration: 1 }
      - { id: B, area: [[0,0],[1,0],[1,1]], earliest_start: 0, latest_finish: 60, duration: 1 }
    depends: { A: [B], B: [A] }
)",
               "cycle");
  expect_error(kNodes + "operations:\n  - { op: fly }\n", "unknown op 'fly'");
  expect_error("nodes:\n  - { id: n1, radius: 0.1, max_speed: .inf, start: [0, 0, 0] }\n",
               "node 'n1' max_speed: must be finite");
  expect_error(kNodes + "world: { static: [[[0,0],[1,0]]] }\n", "world.static[0]");
  expect_error("nodes: [ {id: a", "not valid YAML");
}

const std::string kTwoDependentJobs = R"(operations:
  - op: schedule_dependent
    jobs:
      - { id: A, area: [[1,0],[2,0],[2,1],[1,1]], earliest_start: 0, latest_finish: 60, duration: 5 }
      - { id: B, area: [[3,0],[4,0],[4,1],[3,1]], earliest_start: 0, latest_finish: 60, duration: 5 }
)";

TEST(Problem, DependsNeedsAListOfJobIdsPerJob) {
  // `A: B` was skipped without a word, and A was scheduled before B.
  expect_error(kNodes + kTwoDependentJobs + "    depends: { A: B }\n",
               "p.yaml:9:19: depends.A: expected a list of job ids");
  expect_error(kNodes + kTwoDependentJobs + "    depends: { A: { B: 1 } }\n",
               "depends.A: expected a list of job ids");
  expect_error(kNodes + kTwoDependentJobs + "    depends: [A, B]\n",
               "p.yaml:9:14: depends: expected a mapping of job id to a list of job ids");
  expect_error(kNodes + kTwoDependentJobs + "    depends: { A: [B], A: [] }\n",
               "p.yaml:9:24: depends.A: given twice");
  const auto p = parse_problem(kNodes + kTwoDependentJobs + "    depends: { A: [B] }\n", "p.yaml");
  ASSERT_EQ(p.operations.size(), 1u);
  EXPECT_EQ(p.operations[0].dependent.depends.at("A"), std::vector<std::string>{"B"});
}

TEST(Problem, EveryMappingRefusesUnknownKeys) {
  // A misspelt optional key was ignored: same_locaton: false planned the same location for all.
  const std::string job =
      "{ id: J, area: [[1,0],[2,0],[2,1],[1,1]], earliest_start: 0, "
      "latest_finish: 60, duration: 5";
  const std::vector<std::pair<std::string, std::string>> cases{
      {kNodes + "setings: {}\n",
       "p.yaml:4:1: top level: unknown key 'setings' (expected one of: "
       "world, nodes, settings, operations)"},
      {kNodes + "world: { statics: [] }\n", "p.yaml:4:10: world: unknown key 'statics'"},
      {kNodes + "world: { dynamic: [ { shape: [[0,0],[1,0],[1,1]], trajectory: [[5,5,0]], "
                "speed: 1 } ] }\n",
       "p.yaml:4:74: world.dynamic[0]: unknown key 'speed' (expected one of: shape, trajectory)"},
      {"nodes:\n  - { id: n1, radius: 0.1, max_speed: 0.5, start: [0, 0, 0], turning_radus: 1 }\n",
       "p.yaml:2:62: node 'n1': unknown key 'turning_radus' (expected one of: id, radius, "
       "max_speed, start, turning_radius)"},
      {kNodes + "settings: { location_sample: 3 }\n",
       "p.yaml:4:13: settings: unknown key 'location_sample' (expected one of: present, "
       "frozen_horizon, dependency_margin, location_samples, wait_threshold, seed)"},
      {kNodes + "operations:\n  - { op: schedule, job: " + job + ", duraton: 5 } }\n",
       "p.yaml:5:119: job 'J': unknown key 'duraton' (expected one of: id, area, earliest_start, "
       "latest_finish, duration)"},
      {kNodes + "operations:\n  - { op: schedule, job: " + job + " }, commit: true }\n",
       "p.yaml:5:121: schedule: unknown key 'commit' (expected one of: op, job)"},
      {kNodes + "operations:\n  - { op: reschedule, jobs: " + job + " } }\n",
       "reschedule: unknown key 'jobs'"},
      {kNodes + "operations:\n  - { op: schedule_periodic, ids: [P1, P2], area: "
                "[[1,0],[2,0],[2,1],[1,1]], same_locaton: false, start: 0, period: 20, "
                "duration: 5 }\n",
       "p.yaml:5:78: schedule_periodic: unknown key 'same_locaton' (expected one of: op, ids, "
       "area, same_location, start, period, duration)"},
      {kNodes + "operations:\n  - { op: schedule_dependent, jobs: [], depend: { A: [B] } }\n",
       "p.yaml:5:41: schedule_dependent: unknown key 'depend' (expected one of: op, jobs, "
       "depends)"},
      {kNodes + "operations:\n  - { op: schedule_dependent, jobs: [" + job +
           ", latest_start: 3 }] }\n",
       "job 'J': unknown key 'latest_start'"},
      {kNodes + "operations:\n  - { op: schedule, job: " + job +
           " } }\n  - { op: unschedule, id: J, replan: false }\n",
       "p.yaml:6:30: unschedule: unknown key 'replan' (expected one of: op, id)"},
      {kNodes + "operations:\n  - { op: schedule, job: " + job +
           " } }\n  - { op: remove, job: J }\n",
       "remove: unknown key 'job'"},
      {kNodes + "operations:\n  - { op: commit, nodes: n1 }\n",
       "p.yaml:5:19: commit: unknown key 'nodes' (expected one of: op, transaction, node)"},
      {kNodes + "operations:\n  - { op: abort, tx: 1 }\n", "abort: unknown key 'tx'"},
      {kNodes + "operations:\n  - { op: set_present, time: 5 }\n",
       "p.yaml:5:24: set_present: unknown key 'time' (expected one of: op, t)"},
      {kNodes + "settings: { present: 0, present: 5 }\n",
       "p.yaml:4:25: settings: 'present' given "
       "twice"},
  };
  for (const auto& [text, message] : cases) expect_error(text, message);
}

TEST(Problem, ListsAndBooleansAreWhatTheySay) {
  // A scalar in place of a list was read as an empty list; a mapping or a bad boolean ended with
  // yaml-cpp's message, without the file.
  expect_error(kNodes + "world: { static: 5 }\n", "p.yaml:4:18: world.static: expected a list");
  expect_error(kNodes + "world: { dynamic: { shape: [] } }\n",
               "p.yaml:4:19: world.dynamic: expected a list");
  expect_error("nodes: { id: n1 }\n", "p.yaml:1:8: nodes: expected a list");
  expect_error(kNodes + "operations: { op: commit }\n", "p.yaml:4:13: operations: expected a list");
  expect_error(kNodes + "operations:\n  - { op: schedule_dependent, jobs: A }\n",
               "p.yaml:5:37: schedule_dependent jobs: expected a list");
  expect_error(kNodes +
                   "operations:\n  - { op: schedule_periodic, ids: [P1], area: "
                   "[[1,0],[2,0],[2,1],[1,1]], same_location: maybe, start: 0, period: 20, "
                   "duration: 5 }\n",
               "p.yaml:5:89: schedule_periodic same_location: expected true or false");
  expect_error(kNodes + "world: 5\n", "p.yaml:4:8: world: expected a mapping");
}

TEST(Problem, CountsAreIntegersInTheirRange) {
  // location_samples: 2.7 was truncated to 2, and 1e300 was cast to int (undefined behaviour).
  for (const std::string v : {"2.7", "0", "-3", "10001", "1e300"}) {
    expect_error(
        kNodes + "settings: { location_samples: " + v + " }\n",
        "p.yaml:4:31: settings.location_samples = " + v + ": expected an integer from 1 to 10000");
  }
  EXPECT_EQ(parse_problem(kNodes + "settings: { location_samples: 10000 }\n", "p.yaml")
                .settings.location_samples,
            10000);
  for (const std::string v : {"1.5", "0", "1e300"}) {
    expect_error(
        kNodes + "operations:\n  - { op: commit, transaction: " + v + " }\n",
        "p.yaml:5:32: commit transaction = " + v + ": expected an integer from 1 to 1000000000");
  }
}

TEST(Problem, ANodeTheSchedulerRefusesIsReportedWhereItIsInTheFile) {
  // The scheduler's message came without file and line.
  const auto p = parse_problem(R"(world: { static: [[[-1,-1],[1,-1],[1,1],[-1,1]]] }
nodes:
  - { id: n1, radius: 0.1, max_speed: 0.5, start: [5, 5, 0] }
  - { id: n2, radius: 0.1, max_speed: 0.5, start: [0, 0, 0] }
)",
                               "p.yaml");
  test::expect_error([&] { ProblemRunner runner(p); },
                     "p.yaml:4:5: node 'n2': start lies within radius of a static obstacle");
}

TEST(Problem, ABowTieIsReportedAsSelfIntersecting) {
  // It was "polygon must be simple (not self-intersecting): Geometry has wrong orientation".
  try {
    parse_problem(kNodes + "world: { static: [[[0,0],[1,1],[1,0],[0,1]]] }\n", "p.yaml");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "p.yaml:4:19: world.static[0]: polygon is self-intersecting (two of its edges cross "
              "or touch); it must be simple");
  }
}

TEST(Problem, TheJsonHasEachNodesLoadFromThePresentToTheLastJobsEnd) {
  // n1 drives 2 m at 0.5 m/s (t 0-4) and works 10 s (4-14); n2 stays. With the present at 2 the
  // interval is [2, 14]: n1 L_J = 10/12, L_M = 2/12, L_S = 0, L = 1, L_v = 1 m / (0.5 m/s · 12 s).
  const auto p = parse_problem(R"(
nodes:
  - { id: n1, radius: 0.1, max_speed: 0.5, start: [0, 0, 0] }
  - { id: n2, radius: 0.1, max_speed: 0.5, start: [50, 50, 0] }
operations:
  - { op: schedule, job: { id: J, area: [[1.9,-0.1],[2.1,-0.1],[2.1,0.1],[1.9,0.1]], earliest_start: 0, latest_finish: 100, duration: 10 } }
  - { op: commit }
  - { op: set_present, t: 2 }
)",
                               "p.yaml");
  ProblemRunner runner(p);
  runner.run();
  const auto doc = nlohmann::json::parse(runner.to_json());
  ASSERT_EQ(doc["jobs"].size(), 1u);
  ASSERT_EQ(doc["jobs"][0]["node"], "n1");
  EXPECT_NEAR(doc["jobs"][0]["start"].get<double>(), 4, 1e-9);
  ASSERT_EQ(doc["load_interval"].size(), 2u);
  EXPECT_DOUBLE_EQ(doc["load_interval"][0].get<double>(), 2);
  EXPECT_NEAR(doc["load_interval"][1].get<double>(), 14, 1e-9);
  const auto expect_load = [&](int node, std::vector<double> figures) {
    const auto& load = doc["nodes"][node]["load"];
    int k = 0;
    for (const char* key : {"job", "motion", "stationary", "total", "velocity"}) {
      EXPECT_NEAR(load[key].get<double>(), figures[k++], 1e-9) << "node " << node << " " << key;
    }
  };
  expect_load(0, {10.0 / 12, 2.0 / 12, 0, 1, 1.0 / 6});
  expect_load(1, {0, 0, 1, 0, 0});

  // No committed job after the present: no interval, no load.
  const auto idle_problem = parse_problem(kNodes, "p.yaml");
  ProblemRunner idle(idle_problem);
  idle.run();
  const auto none = nlohmann::json::parse(idle.to_json());
  EXPECT_FALSE(none.contains("load_interval"));
  EXPECT_FALSE(none["nodes"][0].contains("load"));
}

TEST(Problem, TimesTheSchedulerChecksAreCheckedInTheFile) {
  // Both were refused by the scheduler, without the place in the file (the periodic set only as
  // a failed operation, after planning had begun).
  expect_error(kNodes + "settings: { frozen_horizon: 1e300 }\n",
               "p.yaml:4:29: settings.frozen_horizon = 1e+300: times must lie within ±1e6 s");
  expect_error(kNodes +
                   "operations:\n  - { op: schedule_periodic, ids: [P1, P2, P3], area: "
                   "[[1,0],[2,0],[2,1],[1,1]], start: 999990, period: 20, duration: 5 }\n",
               "p.yaml:5:5: schedule_periodic: the last repetition ends at start + 3·period = "
               "1000050: times must lie within ±1e6 s");
}

}  // namespace
}  // namespace oscar::swarm

namespace oscar::swarm {
namespace {

TEST(Problem, SetsAreUnscheduledWholeAndDoneNodesRemoved) {
  const auto p = parse_problem(R"(
nodes:
  - { id: n1, radius: 0.1, max_speed: 1, start: [0, 0, 0] }
  - { id: n2, radius: 0.1, max_speed: 1, start: [0, 10, 0] }
operations:
  - { op: schedule_periodic, ids: [P1, P2], area: [[1,1],[2,1],[2,2],[1,2]], start: 5, period: 10, duration: 2 }
  - { op: commit }
  - { op: unschedule, id: P2 }
  - { op: unschedule_set, id: P2 }
  - { op: commit }
  - { op: remove_node, node: n2 }
)",
                               "p.yaml");
  ProblemRunner runner(p);
  runner.run();
  const auto doc = nlohmann::json::parse(runner.to_json());
  const auto& ops = doc["operations"];
  ASSERT_EQ(ops.size(), 6u);
  EXPECT_FALSE(ops[2]["ok"]);
  EXPECT_NE(ops[2]["reason"].get<std::string>().find("belongs to the periodic set P1, P2"),
            std::string::npos);
  EXPECT_TRUE(ops[3]["ok"]);
  EXPECT_TRUE(ops[5]["ok"]) << ops[5];
  EXPECT_TRUE(doc["jobs"].empty());
  EXPECT_EQ(runner.scheduler().node_ids(), std::vector<std::string>{"n1"});
  expect_error(kNodes + "operations:\n  - { op: remove_node, node: n7 }\n",
               "p.yaml:5:30: remove_node: unknown node id 'n7'");
}

TEST(Problem, LiveOperationsTakeOnlyWhatARunningSwarmDoes) {
  const auto ops = parse_operations(R"(
- { op: schedule, job: { id: J1, area: [[4,2],[6,2],[6,4],[4,4]], earliest_start: 10, latest_finish: 60, duration: 10 } }
- { op: unschedule, id: J0 }
- { op: unschedule_set, id: P1 }
)",
                                    "jobs.yaml");
  ASSERT_EQ(ops.size(), 3u);
  EXPECT_EQ(ops[1].id, "J0");  // submitted before: the coordinator knows it
  EXPECT_EQ(ops[2].kind, Operation::Kind::kUnscheduleSet);
  test::expect_error([] { parse_operations("- { op: commit }\n", "jobs.yaml"); },
                     "jobs.yaml:1:3: commit: not for a live swarm");
  test::expect_error(
      [] {
        parse_job(
            "{id: J, area: [[0,0],[1,0]], earliest_start: 0, "
            "latest_finish: 9, duration: 1}",
            "--job 1");
      },
      "--job 1:1:15: job 'J' area");
}

}  // namespace
}  // namespace oscar::swarm
