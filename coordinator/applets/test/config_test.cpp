#include "oscar/applets/config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/applets/scenario.hpp"

namespace oscar::applets {
namespace {

using ::testing::HasSubstr;

std::string error_of(const std::string& yaml) {
  try {
    Scenario::parse(yaml, "sys.yaml");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no exception";
}

TEST(Config, LoadsServicesDependenciesAppletsAndParams) {
  const auto s = Scenario::parse(R"(
scheduler: {revoke_wait_ms: 1500, negotiation_rounds: 5}
services:
  - {name: Pilot}
  - {name: Dock, depends_on: [Pilot]}
  - {name: UI, exclusive_only: true}
applets:
  - name: UIService
    provides: [UI]
    params: {Menu: /Scheduler/Menu}
    bundles: [{name: io, priority: 250, requested: true, resources: [{service: Pilot, access: shared}]}]
timeline: []
)",
                                 "sys.yaml");
  const SystemConfig& c = s.system();
  EXPECT_EQ(c.options.revoke_wait, milliseconds{1500});
  EXPECT_EQ(c.options.negotiation_rounds_max, 5);
  EXPECT_EQ(c.model.service(c.model.service_id("Dock")).dependencies.size(), 1u);
  EXPECT_TRUE(c.model.service(c.model.service_id("UI")).exclusive_only);
  EXPECT_EQ(c.applet_params.at("UIService").at("Menu"), "/Scheduler/Menu");
  EXPECT_EQ(c.model.bundle(0).priority, 250);
  EXPECT_EQ(c.requested_at_start, std::vector<BundleId>{0});
}

TEST(Config, ABundlesDeadlineCountsFromEachRequestAndIsCheckedWithItsLine) {
  const auto s = Scenario::parse(R"(
services: [ {name: Pilot} ]
applets:
  - name: Cal
    bundles: [{name: drive, deadline: {early_ms: 5000, duration_ms: 1000, finish_ms: 6000},
               resources: [{service: Pilot}]}]
timeline: []
)",
                                 "sys.yaml");
  const auto& d = s.system().model.bundle(0).request_deadline;
  ASSERT_TRUE(d);
  EXPECT_EQ(d->t_early, milliseconds{5000});
  EXPECT_EQ(d->t_duration, milliseconds{1000});
  EXPECT_EQ(d->t_finish, milliseconds{6000});

  const std::string head =
      "scheduler: {context_switch_ms: 100}\nservices: [ {name: P} ]\napplets:\n  - name: A\n"
      "    bundles: [{name: b, resources: [{service: P}], deadline: ";
  EXPECT_THAT(error_of(head + "{early_ms: 0, duration_ms: 950, finish_ms: 1000}}]\ntimeline: []\n"),
              HasSubstr("sys.yaml:5: applet 'A' bundle 'b': deadline needs early_ms + duration_ms "
                        "+ context_switch_ms <= finish_ms (eq. 4.9), but 0 + 950 + 100 > 1000"));
  EXPECT_THAT(error_of(head + "{early_ms: 0}}]\ntimeline: []\n"),
              HasSubstr("sys.yaml:5: applet 'A' bundle 'b': deadline needs finish_ms"));
  EXPECT_THAT(error_of(head + "{finish: 10}}]\ntimeline: []\n"), HasSubstr("finish"));
  EXPECT_THAT(error_of(head + "5000}]\ntimeline: []\n"),
              HasSubstr("deadline must be a map such as {early_ms: 0"));
}

// The long form of a dependency used to throw yaml-cpp's "operator[] call on a scalar": reading
// its service rewrote the entry it came from.
TEST(Config, ADependencysLongFormGivesItsServiceAndAccess) {
  const auto s = Scenario::parse(R"(
services:
  - {name: Pilot}
  - {name: Map}
  - {name: Dock, depends_on: [{service: Pilot, access: shared}, Map]}
timeline: []
)",
                                 "sys.yaml");
  const auto& model = s.system().model;
  const auto& deps = model.service(model.service_id("Dock")).dependencies;
  ASSERT_EQ(deps.size(), 2u);
  EXPECT_EQ(deps[0].service, model.service_id("Pilot"));
  EXPECT_EQ(deps[0].access, Access::kShared);
  EXPECT_EQ(deps[1].service, model.service_id("Map"));
  EXPECT_EQ(deps[1].access, Access::kExclusive);
}

TEST(Config, MalformedYamlGivesFileLineAndColumn) {
  EXPECT_THAT(error_of("services:\n  - {name: Pilot\n"), HasSubstr("sys.yaml:3:"));
  EXPECT_THAT(error_of("services:\n  - {name: Pilot\n"), HasSubstr("malformed YAML"));
}

TEST(Config, UnknownServiceInABundleIsNamedWithItsLine) {
  EXPECT_THAT(error_of(R"(services: [{name: Pilot}]
applets:
  - name: A
    bundles:
      - name: b
        resources:
          - {service: Pilott}
timeline: []
)"),
              HasSubstr("sys.yaml:7: applet 'A' bundle 'b': unknown service 'Pilott'"));
}

TEST(Config, DependencyOnAMissingServiceIsNamed) {
  EXPECT_THAT(error_of("services:\n  - {name: Dock, depends_on: [Pilot]}\ntimeline: []\n"),
              HasSubstr("sys.yaml:2: service 'Dock' depends on unknown service 'Pilot'"));
}

TEST(Config, UnknownKeyAndBadAccessAndBadPriorityAreNamed) {
  EXPECT_THAT(error_of("services:\n  - {name: P, exclusive: true}\ntimeline: []\n"),
              HasSubstr("sys.yaml:2: service: unknown key 'exclusive'"));
  EXPECT_THAT(error_of(R"(services: [{name: P}]
applets: [{name: A, bundles: [{name: b, resources: [{service: P, access: mine}]}]}]
timeline: []
)"),
              HasSubstr("sys.yaml:2: access 'mine' must be 'shared' or 'exclusive'"));
  EXPECT_THAT(error_of(R"(services: [{name: P}]
applets: [{name: A, bundles: [{name: b, priority: urgent, resources: [{service: P}]}]}]
timeline: []
)"),
              HasSubstr("priority 'urgent' must be low, normal, high, system"));
}

TEST(Config, SharedRequestOfAnExclusiveOnlyServiceIsRejected) {
  EXPECT_THAT(error_of(R"(services: [{name: UI, exclusive_only: true}]
applets: [{name: A, bundles: [{name: b, resources: [{service: UI, access: shared}]}]}]
timeline: []
)"),
              HasSubstr("sys.yaml:2: applet 'A' bundle 'b' asks for shared access to "
                        "exclusive-only service 'UI'"));
}

// Two bundles of one applet requested at start that both want an exclusive-only service.
TEST(Config, TwoRequestedBundlesOnOneExclusiveOnlyServiceAreRejectedWithTheLine) {
  EXPECT_THAT(error_of(R"(services: [{name: UI, exclusive_only: true}]
applets:
  - name: Battery
    bundles:
      - {name: warn, requested: true, resources: [{service: UI}]}
      - {name: dock, requested: true, resources: [{service: UI}]}
timeline: []
)"),
              HasSubstr("sys.yaml:6: applet 'Battery' requests bundle 'dock' with service 'UI' "
                        "which its requested bundle 'warn' already uses"));
}

TEST(Config, TimelineErrorsNameTheLine) {
  const std::string sys = R"(services: [{name: P}]
applets: [{name: A, bundles: [{name: b, resources: [{service: P}]}]}]
timeline:
)";
  EXPECT_THAT(error_of(sys + "  - {request: A/c}\n"),
              HasSubstr("sys.yaml:4: applet 'A' has no bundle 'c'"));
  EXPECT_THAT(error_of(sys + "  - {request: Ab}\n"),
              HasSubstr("must name a bundle as applet/bundle"));
  EXPECT_THAT(error_of(sys + "  - {jump: A/b}\n"),
              HasSubstr("sys.yaml:4: step: unknown key 'jump'"));
  // Refused at run time (eq. 4.9): the message names the event's line.
  const auto s = Scenario::parse(
      sys + "  - {set_deadline: A/b, t_early_ms: 0, t_duration_ms: 50, t_finish_ms: 10}\n",
      "sys.yaml");
  try {
    s.run();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("sys.yaml:4: applet 'A' bundle 'b': deadline needs"));
  }
}

// An event's keys are checked like every other mapping's: a misspelt field inside do: (or beside
// an event written in the step) is an error naming it, not an event without it.
TEST(Config, UnknownKeyInsideAnEventIsNamedWithItsLine) {
  const std::string sys = R"(services: [{name: P}]
applets: [{name: A, bundles: [{name: b, resources: [{service: P}]}]}]
timeline:
)";
  EXPECT_THAT(error_of(sys + "  - do: [{request: A/b, trigerr: true}]\n"),
              HasSubstr("sys.yaml:4: event 'request': unknown key 'trigerr' (allowed: request, "
                        "trigger)"));
  EXPECT_THAT(error_of(sys + "  - do:\n      - {set_priority: A/b, priority: high, clear: true}\n"),
              HasSubstr("sys.yaml:5: event 'set_priority': unknown key 'clear' (allowed: "
                        "set_priority, priority)"));
  EXPECT_THAT(error_of(sys + "  - {label: x, set_priority: A/b, priorty: high}\n"),
              HasSubstr("sys.yaml:4: step: unknown key 'priorty'"));
  EXPECT_THAT(error_of(sys + "  - {label: x, set_priority: A/b, priority: high, accept: true}\n"),
              HasSubstr("sys.yaml:4: event 'set_priority': unknown key 'accept'"));
  EXPECT_THAT(error_of(sys + "  - {do: [{release: A/b}], priority: high}\n"),
              HasSubstr("sys.yaml:4: step: 'priority' beside 'do'"));
  EXPECT_THAT(error_of(sys + "  - {request: A/b, trigger: maybe}\n"),
              HasSubstr("sys.yaml:4: trigger must be true or false"));
  EXPECT_THAT(error_of(sys + "  - {foo_ms: 3}\n"),
              HasSubstr("sys.yaml:4: step: unknown key 'foo_ms'"));
}

// A scalar where a list belongs used to read as an empty list (provides: S provided nothing).
TEST(Config, ScalarWhereAListBelongsIsAnError) {
  EXPECT_THAT(
      error_of(R"(services: [{name: S}]
applets:
  - name: A
    provides: S
timeline: []
)"),
      HasSubstr("sys.yaml:4: applet 'A': provides must be a list of services, such as [UI]"));
  EXPECT_THAT(error_of(R"(services: [{name: S}]
applets:
  - name: A
    bundles: {name: b, resources: [{service: S}]}
timeline: []
)"),
              HasSubstr("sys.yaml:4: applet 'A': bundles must be a list of bundles"));
  EXPECT_THAT(error_of("services: [{name: S, exclusive_only: sometimes}]\ntimeline: []\n"),
              HasSubstr("sys.yaml:1: exclusive_only must be true or false"));
}

}  // namespace
}  // namespace oscar::applets
