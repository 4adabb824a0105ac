#include "oscar/swarm_yaml.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace oscar {
namespace {

Trajectory sample() {
  Trajectory t;
  t.robot("r'1");
  t.transaction(7);
  TrajectorySection s;
  s.from_ns(1'700'000'000'123'456'789);
  s.to_ns(1'700'000'010'000'000'001);
  s.open_end(true);
  for (const auto& [x, y, dt] : {std::tuple{0.1, -2.5, 0LL}, {1.0 / 3, 1e-7, 9'876'543'212LL}}) {
    SwarmWaypoint w;
    w.x(x);
    w.y(y);
    w.t_ns(s.from_ns() + dt);
    s.waypoints().push_back(w);
  }
  t.sections().push_back(s);
  RobotJob j;
  j.id("pick: 3");
  j.x(12.25);
  j.y(-0.5);
  j.start_ns(1'700'000'005'000'000'000);
  j.end_ns(1'700'000'008'000'000'000);
  j.earliest_start_ns(1'700'000'001'000'000'000);
  j.latest_finish_ns(1'700'000'060'000'000'000);
  t.jobs_added().push_back(j);
  t.jobs_removed({"old"});
  return t;
}

TEST(SwarmYaml, ATrajectoryComesBackExactly) {
  const Trajectory t = sample();
  const std::string text = to_yaml(t);
  EXPECT_EQ(text.find('\n'), std::string::npos) << text;
  EXPECT_EQ(trajectory_from_yaml(text), t) << text;
}

TEST(SwarmYaml, ReadsTheFormOscarConfigTakes) {
  const auto t = trajectory_from_yaml(
      "{robot: r1, transaction: 7, sections: [{from_ns: 10, open_end: true, waypoints: "
      "[{x: 0, y: 0, t_ns: 10}, {x: 1, y: 0, t_ns: 20}]}]}");
  EXPECT_EQ(t.robot(), "r1");
  ASSERT_EQ(t.sections().size(), 1u);
  EXPECT_TRUE(t.sections()[0].open_end());
  EXPECT_EQ(t.sections()[0].to_ns(), 0);  // left out: the IDL default
  EXPECT_EQ(t.sections()[0].waypoints()[1].t_ns(), 20);
  EXPECT_TRUE(t.jobs_added().empty());
}

TEST(SwarmYaml, BadTextNamesTheMemberAndTheRule) {
  auto error = [](const std::string& text) {
    try {
      trajectory_from_yaml(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("[1, 2]"), "trajectory: expected a map");
  EXPECT_EQ(error("{robot: r1, speed: 3}"), "speed: no such member");
  EXPECT_EQ(error("{sections: [{waypoints: [{x: 0, t_ns: 1.5}]}]}"),
            "sections[0].waypoints[0].t_ns: '1.5' is no integer");
  EXPECT_EQ(error("{sections: {from_ns: 1}}"), "sections: expected a list");
  EXPECT_EQ(error("{jobs_added: [{id: j, x: far}]}"), "jobs_added[0].x: 'far' is no number");
  EXPECT_NE(error("{robot: [r1").find("trajectory: no YAML"), std::string::npos);
}

}  // namespace
}  // namespace oscar
