// The pictures of oscar swarm plan --svg: axes with values in metres and seconds, every moving
// obstacle inside the picture, no job label on top of another.
#include "svg.hpp"

#include <regex>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/swarm/load.hpp"
#include "oscar/swarm/problem_runner.hpp"
#include "source_tree.hpp"

namespace oscar::swarm::tools {
namespace {
using ::testing::HasSubstr;

// A problem planned as oscar swarm plan does (the runner refers to the problem: both live here).
struct Planned {
  explicit Planned(const std::string& example)
      : problem(load_problem(oscar::testing::source_path("coordinator/swarm/examples/") + example)),
        runner(problem) {
    runner.run();
  }
  const Scheduler& scheduler() const { return runner.scheduler(); }
  Problem problem;
  ProblemRunner runner;
};

struct Text {
  double x, y;
  std::string text;
};

std::vector<Text> texts(const std::string& svg) {
  static const std::regex re(R"re(<text x="([-\d.]+)" y="([-\d.]+)"[^>]*>([^<]*)</text>)re");
  std::vector<Text> out;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator();
       ++it) {
    out.push_back({std::stod((*it)[1]), std::stod((*it)[2]), (*it)[3]});
  }
  return out;
}

TEST(SwarmSvg, TheWorldHasAxesInMetresAndNoJobLabelOnAnother) {
  const auto svg = world_svg(Planned("job_sets.yaml").scheduler());
  EXPECT_THAT(svg, HasSubstr(">x [m]</text>"));
  EXPECT_THAT(svg, HasSubstr(">y [m]</text>"));
  std::vector<Text> jobs;
  for (const auto& t : texts(svg)) {
    if (t.text.find(" @") != std::string::npos) jobs.push_back(t);
  }
  ASSERT_GE(jobs.size(), 4u);
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    for (std::size_t j = i + 1; j < jobs.size(); ++j) {
      const bool apart =
          std::abs(jobs[i].y - jobs[j].y) >= 12 ||
          std::abs(jobs[i].x - jobs[j].x) >=
              6.2 * static_cast<double>(std::max(jobs[i].text.size(), jobs[j].text.size()));
      EXPECT_TRUE(apart) << jobs[i].text << " and " << jobs[j].text << " overlap";
    }
  }
}

TEST(SwarmSvg, EveryShapeLiesInsideThePicture) {
  for (const auto* example : {"job_sets.yaml", "worked_example.yaml"}) {
    const auto svg = world_svg(Planned(example).scheduler());
    static const std::regex point(R"((-?[\d.]+),(-?[\d.]+) )");
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), point);
         it != std::sregex_iterator(); ++it) {
      const double x = std::stod((*it)[1]), y = std::stod((*it)[2]);
      EXPECT_TRUE(x >= 0 && x <= 800 && y >= 0 && y <= 820) << example << ": " << x << "," << y;
    }
  }
}

TEST(SwarmSvg, TheStDiagramHasAxesInMetresAndSeconds) {
  const Planned planned("worked_example.yaml");
  const auto svg = st_svg(planned.scheduler(), planned.scheduler().node_ids().front());
  EXPECT_THAT(svg, HasSubstr(">s along the path [m]</text>"));
  EXPECT_THAT(svg, HasSubstr(">t [s]</text>"));
  EXPECT_GE(texts(svg).size(), 10u) << "tick values";
}

}  // namespace
}  // namespace oscar::swarm::tools
