#include "oscar/applets/dot.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/applets/scenario.hpp"

namespace oscar::applets {
namespace {

using ::testing::HasSubstr;

TEST(Dot, ShowsAppletsBundlesServicesStatesAndPriorities) {
  const auto s = Scenario::parse(
      R"(services: [{name: Pilot}, {name: Dock, depends_on: [Pilot]}, {name: UI, exclusive_only: true}]
applets:
  - {name: UIService, provides: [UI], bundles: [{name: io, priority: system, resources: [{service: Pilot, access: shared}]}]}
  - {name: Battery, bundles: [{name: d, priority: 250, resources: [{service: Dock}]}]}
timeline:
  - {request: Battery/d}
)",
      "d.yaml");
  Scheduler final_state(s.system().model, s.system().options);
  s.run(&final_state);
  const std::string dot = to_dot(final_state);
  EXPECT_THAT(dot, HasSubstr("digraph applets"));
  EXPECT_THAT(dot, HasSubstr("UIService (service applet)"));
  EXPECT_THAT(
      dot,
      HasSubstr(
          R"("b:Battery/d" [shape=box, style=filled, fillcolor=palegreen, label="d\nprio 250\nactive"])"));
  EXPECT_THAT(dot, HasSubstr(R"(label="io\nprio system\nidle")"));
  EXPECT_THAT(dot, HasSubstr(R"("s:Dock" -> "s:Pilot" [style=dashed, label="needs exclusive"])"));
  EXPECT_THAT(dot, HasSubstr(R"(label="UI\n(exclusive only)\nblocked")"));
  EXPECT_THAT(dot, HasSubstr(R"("b:Battery/d" -> "s:Dock" [color=red)"));
  // The legend names every colour the picture uses.
  EXPECT_THAT(dot, HasSubstr("subgraph cluster_legend"));
  for (const auto* entry :
       {R"([fillcolor=palegreen, label="bundle active"])",
        R"([fillcolor=khaki, label="bundle granted, waiting for hand-over"])",
        R"([fillcolor=lightgrey, label="bundle blocked"])",
        R"([fillcolor=orange, label="bundle being revoked"])",
        R"([fillcolor=white, label="bundle idle"])",
        R"(fillcolor=lightblue, label="service in use")",
        R"([color=red, label="exclusive, granted")",
        R"x([color=darkgreen, dir=back, label="provides (from a service applet)")x",
        R"x([style=dashed, label="needs (a service's dependency)")x",
        R"([color=blue, label="shared, granted")",
        R"([color=grey, label="requested, not granted")"}) {
    EXPECT_THAT(dot, HasSubstr(entry));
  }
}

TEST(Dot, ShowsABundleBeingRevokedAndAnInheritedActiveOne) {
  const auto s = Scenario::parse(
      R"(services: [{name: UI, exclusive_only: true}, {name: Monitor}]
applets:
  - {name: UIService, provides: [UI], bundles: [{name: io, resources: [{service: Monitor}]}]}
  - {name: Menu, bundles: [{name: ui, resources: [{service: UI}]}]}
  - {name: Battery, bundles: [{name: warn, priority: high, resources: [{service: UI}]}]}
runner: {auto_yield: false}
timeline:
  - {request: Menu/ui}
  - {t_ms: 1000, request: Battery/warn}
)",
      "d.yaml");
  Scheduler final_state(s.system().model, s.system().options);
  s.run(&final_state);
  const std::string dot = to_dot(final_state);
  EXPECT_THAT(
      dot, HasSubstr(R"(fillcolor=orange, label="ui\nprio normal\nbeing revoked, until 6000 ms")"));
  EXPECT_THAT(dot, HasSubstr(R"(label="io\nprio normal\nactive")"));  // inherited, not requested
}

// A service applet without bundles: its provides edge starts at a node of its own inside its
// box (it used to start at an undrawn "b:Clock/<another applet's bundle>" node, which Graphviz
// draws as a phantom ellipse outside every box).
TEST(Dot, ServiceAppletWithoutBundlesHasNoPhantomNode) {
  const auto s = Scenario::parse(
      R"(services: [{name: Time}, {name: Pilot}]
applets:
  - {name: Clock, provides: [Time]}
  - {name: Driver, bundles: [{name: d, resources: [{service: Pilot}, {service: Time, access: shared}]}]}
timeline:
  - {request: Driver/d}
)",
      "d.yaml");
  Scheduler final_state(s.system().model, s.system().options);
  s.run(&final_state);
  const std::string dot = to_dot(final_state);
  EXPECT_THAT(dot, HasSubstr(R"("a:Clock" [shape=box, style=dashed, label="Clock\nno bundles"])"));
  EXPECT_THAT(dot, HasSubstr(R"("a:Clock" -> "s:Time" [dir=back, color=darkgreen)"));
  // Every node an edge names is declared: no "b:" node appears only in edges.
  for (std::size_t at = dot.find("\"b:"); at != std::string::npos; at = dot.find("\"b:", at + 1)) {
    const std::string node = dot.substr(at, dot.find('"', at + 1) - at + 1);
    EXPECT_THAT(dot, HasSubstr(node + " [shape=box")) << node << " is drawn but never declared";
  }
}

}  // namespace
}  // namespace oscar::applets
