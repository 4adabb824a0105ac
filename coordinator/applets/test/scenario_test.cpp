#include "oscar/applets/scenario.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include "source_tree.hpp"

namespace oscar::applets {
namespace {

std::string scenario_path(const std::string& name) {
  return oscar::testing::source_path("coordinator/applets/scenarios/") + name;
}

// Seed 000 Abb. 5.4, transcribed: UI service, Pilot, Docking-Controller per step
// (Hauptmenü = Menu, Batterie-App = Battery, Kalender = Calendar, blockiert = blocked).
const std::vector<std::vector<std::string>> kAbb54 = {
    {"Menu", "undef", "undef"},          {"DriveTo", "DriveTo", "blocked"},
    {"Battery", "blocked", "Battery"},   {"DriveTo", "DriveTo", "blocked"},
    {"Calendar", "Calendar", "blocked"}, {"DriveTo", "DriveTo", "blocked"},
    {"Menu", "undef", "undef"}};

std::string holder_of(const StepResult& r, const std::string& service) {
  for (const auto& [s, h] : r.holders) {
    if (s == service) return h;
  }
  return "?";
}

// On the logical clock of a scenario, a reservation for later is planned at its t_early and its
// request expires at t_finish, with notes for both (seed §4.5.1).
TEST(Scenario, ReservationIsPlannedAtItsEarliestStartAndExpiresAtItsFinish) {
  const auto s = Scenario::parse(R"(services: [{name: Pilot}]
applets:
  - {name: Battery, bundles: [{name: dock, resources: [{service: Pilot}]}]}
  - {name: DriveTo, bundles: [{name: drive, resources: [{service: Pilot}]}]}
timeline:
  - label: battery reserves 5000-6000 ms
    do:
      - {set_deadline: Battery/dock, t_early_ms: 5000, t_duration_ms: 1000, t_finish_ms: 6000}
      - {request: Battery/dock}
      - {request: DriveTo/drive}
    expect: {Pilot: DriveTo}
  - {label: before, t_ms: 4999, expect: {Pilot: DriveTo}}
  - {label: t_early, t_ms: 5000, expect: {Pilot: Battery}, expect_active: {Pilot: Battery}}
  - {label: after t_finish, t_ms: 6500, expect: {Pilot: DriveTo}, expect_active: {Pilot: DriveTo}}
)",
                                 "r.yaml");
  const auto results = s.run();
  for (const auto& r : results) EXPECT_TRUE(r.mismatches.empty()) << r.mismatches[0];
  const auto& expired = results[3].notes;
  EXPECT_NE(std::find(expired.begin(), expired.end(),
                      "Battery/dock: deadline expired (t_finish 6000 ms), request withdrawn"),
            expired.end());
}

TEST(Scenario, RealWorldScenarioReproducesAbb54TwentyTimes) {
  const Scenario s = Scenario::load_file(scenario_path("real_world_5_3.yaml"));
  std::string first;
  for (int run = 0; run < 20; ++run) {
    const auto results = s.run();
    ASSERT_EQ(results.size(), kAbb54.size());
    for (std::size_t i = 0; i < results.size(); ++i) {
      EXPECT_EQ(holder_of(results[i], "UI"), kAbb54[i][0]) << "run " << run << " step " << i + 1;
      EXPECT_EQ(holder_of(results[i], "Pilot"), kAbb54[i][1]) << "run " << run << " step " << i + 1;
      EXPECT_EQ(holder_of(results[i], "DockingController"), kAbb54[i][2])
          << "run " << run << " step " << i + 1;
      EXPECT_TRUE(results[i].mismatches.empty());
      // Battery, Monitor and MouseClick have one resource each (seed §5.3.2).
      EXPECT_EQ(holder_of(results[i], "Monitor"), "UIService");
    }
    const std::string json = format_json(results);
    if (run == 0) first = json;
    EXPECT_EQ(json, first) << "run " << run << " differs";
  }
}

TEST(Scenario, ExpectationMismatchIsReported) {
  const auto s = Scenario::parse(R"(services: [{name: P}]
applets: [{name: A, bundles: [{name: b, resources: [{service: P}]}]}]
timeline:
  - {request: A/b, expect: {P: B}}
)",
                                 "m.yaml");
  const auto r = s.run();
  ASSERT_EQ(r[0].mismatches.size(), 1u);
  EXPECT_THAT(r[0].mismatches[0], ::testing::HasSubstr("service P: expected B, got A"));
}

TEST(Scenario, JsonHasStepsEventTimeAndHolders) {
  const auto s = Scenario::parse(R"(services: [{name: P}, {name: Q}]
applets: [{name: A, bundles: [{name: b, resources: [{service: P}]}]}]
timeline:
  - {label: go, t_ms: 10, request: A/b}
)",
                                 "j.yaml");
  EXPECT_THAT(format_json(s.run()), ::testing::HasSubstr(R"("event": "go",
      "t_ms": 10,
      "holders": {
        "P": "A",
        "Q": "undef"
      })"));
}

TEST(Scenario, AppendixCounterScenarioSwitchesSharedAndExclusive) {
  const Scenario s = Scenario::load_file(scenario_path("appendix_counter.yaml"));
  for (const auto& r : s.run()) EXPECT_TRUE(r.mismatches.empty()) << r.mismatches[0];
}

TEST(Scenario, PrioritiesDeadlinesScenarioReportsTheOverlapToBoth) {
  const Scenario s = Scenario::load_file(scenario_path("priorities_deadlines.yaml"));
  const auto results = s.run();
  for (const auto& r : results) EXPECT_TRUE(r.mismatches.empty()) << r.mismatches[0];
  const auto& notes = results.at(4).notes;
  EXPECT_NE(std::find(notes.begin(), notes.end(), "App3/s2: deadline overlaps App4/s2"),
            notes.end());
  EXPECT_NE(std::find(notes.begin(), notes.end(), "App4/s2: deadline overlaps App3/s2"),
            notes.end());
}

TEST(Scenario, NegotiationScenarioRunsAsDocumented) {
  const Scenario s = Scenario::load_file(scenario_path("negotiation.yaml"));
  for (const auto& r : s.run()) EXPECT_TRUE(r.mismatches.empty()) << r.mismatches[0];
}

}  // namespace
}  // namespace oscar::applets
