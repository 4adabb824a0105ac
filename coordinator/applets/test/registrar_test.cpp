// Services and applets added to and removed from a running Scheduler and Runtime (seed 000
// §4.1.1: the scheduler is the registrar of services and applets).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>

#include "oscar/applets/config.hpp"
#include "oscar/applets/runtime.hpp"
#include "oscar/applets/scheduler.hpp"
#include "test_support.hpp"

namespace oscar::applets {
namespace {

using namespace std::chrono_literals;
using testing::error_of;
using testing::eventually;
using ::testing::HasSubstr;
constexpr auto kX = Access::kExclusive;
constexpr auto kS = Access::kShared;

NewApplet applet(std::string name, std::string bundle, std::string service, int priority,
                 Access access = kX) {
  return NewApplet{
      std::move(name),
      false,
      {},
      {NewBundle{std::move(bundle), priority, {{std::move(service), access}}, std::nullopt}}};
}

// One service S and applet Low with bundle s.
struct Base {
  Model m;
  ServiceId svc = m.add_service("S");
  AppletId low_applet = m.add_applet("Low");
  BundleId low = m.add_bundle(low_applet, "s", {{svc, kX}}, kPriorityNormal);
};

TEST(Registrar, AnAddedAppletIsPlannedAndPreemptsByPriority) {
  Base t;
  Scheduler s(t.m);
  s.request(t.low);
  const auto ids = s.add(ModelAddition{{}, {applet("High", "s", "S", kPriorityHigh)}});
  ASSERT_EQ(ids.applets.size(), 1u);
  EXPECT_EQ(ids.applets[0], 1u);
  const BundleId high = s.model().bundle_id(ids.applets[0], "s");
  EXPECT_FALSE(s.requested(high));
  EXPECT_EQ(s.priority(high), kPriorityHigh);
  EXPECT_EQ(s.holder(t.svc), "Low");
  s.request(high);
  EXPECT_EQ(s.holder(t.svc), "High");
}

TEST(Registrar, AnAddedServiceWithNeedsGrantsWhatItNeeds) {
  Base t;
  Scheduler s(t.m);
  ModelAddition add;
  add.services.push_back(NewService{"Dock", false, {{"S", kX}}});
  add.applets.push_back(applet("Docker", "d", "Dock", kPriorityNormal));
  const auto ids = s.add(add);
  const ServiceId dock = ids.services.at(0);
  s.request(s.model().bundle_id(ids.applets.at(0), "d"));
  EXPECT_EQ(s.holder(dock), "Docker");
  EXPECT_EQ(s.holder(t.svc), "blocked");  // held up by Dock, which needs it
  s.request(t.low);
  EXPECT_FALSE(s.plan().bundle_granted[t.low]);
}

TEST(Registrar, AFailedAdditionChangesNothing) {
  Base t;
  Scheduler s(t.m);
  ModelAddition add;
  add.services.push_back(NewService{"T", false, {}});
  add.applets.push_back(applet("A", "b", "T", kPriorityNormal));
  add.applets.push_back(applet("B", "b", "Nowhere", kPriorityNormal));
  EXPECT_THAT(error_of([&] { s.add(add); }), HasSubstr("unknown service 'Nowhere'"));
  EXPECT_EQ(s.model().services().size(), 1u);
  EXPECT_EQ(s.model().applets().size(), 1u);
  EXPECT_FALSE(s.model().find_service("T"));
  add.applets.pop_back();
  add.applets.back().bundles.back().priority = -1;
  EXPECT_THAT(error_of([&] { s.add(add); }),
              HasSubstr("applet 'A' bundle 'b': priority must not be negative"));
  EXPECT_EQ(s.model().applets().size(), 1u);
}

TEST(Registrar, ANameInUseIsRefused) {
  Base t;
  Scheduler s(t.m);
  EXPECT_THAT(error_of([&] {
                s.add({{NewService{"S", false, {}}}, {}});
              }),
              HasSubstr("service 'S' is declared twice"));
  EXPECT_THAT(error_of([&] {
                s.add({{}, {applet("Low", "x", "S", 1)}});
              }),
              HasSubstr("applet 'Low' is declared twice"));
}

TEST(Registrar, ARemovedAppletsBundlesAreReleasedAndWaitersGranted) {
  Base t;
  const BundleId high = t.m.add_bundle(t.m.add_applet("High"), "s", {{t.svc, kX}}, kPriorityHigh);
  Scheduler s(t.m);
  s.request(t.low);
  s.request(high);
  s.yield(t.low);
  ASSERT_TRUE(s.active(high));
  s.take_notifications();
  s.remove_applet(1);
  EXPECT_TRUE(s.removed(1));
  EXPECT_FALSE(s.requested(high));
  EXPECT_FALSE(s.active(high));
  EXPECT_TRUE(s.active(t.low));
  EXPECT_EQ(s.holder(t.svc), "Low");
  for (const auto& n : s.take_notifications()) EXPECT_NE(n.applet, 1u);
  EXPECT_THAT(error_of([&] { s.model().applet_id("High"); }), HasSubstr("unknown applet 'High'"));
  EXPECT_THAT(error_of([&] { s.request(high); }),
              HasSubstr("applet 'High' requests bundle 's' but the applet was removed"));
  EXPECT_THAT(error_of([&] { s.remove_applet(1); }),
              HasSubstr("applet 'High' was removed already"));
}

TEST(Registrar, IdsAreNeverReusedAndANameMayComeBack) {
  Base t;
  Scheduler s(t.m);
  s.remove_applet(t.low_applet);
  const auto ids = s.add({{}, {applet("Low", "s", "S", kPriorityNormal)}});
  EXPECT_EQ(ids.applets.at(0), 1u);  // not 0
  EXPECT_EQ(s.model().applet_id("Low"), 1u);
  const BundleId again = s.model().bundle_id(1, "s");
  EXPECT_NE(again, t.low);
  s.request(again);
  EXPECT_EQ(s.holder(t.svc), "Low");
}

TEST(Registrar, ServicesOfARemovedServiceAppletAreUnavailableUntilProvidedAgain) {
  Model m;
  const ServiceId ui = m.add_service("UI");
  const ServiceId monitor = m.add_service("Monitor");
  const AppletId provider = m.add_applet("UIService");
  m.provide(provider, ui);
  m.add_bundle(provider, "io", {{monitor, kX}});
  const BundleId menu = m.add_bundle(m.add_applet("Menu"), "ui", {{ui, kX}});
  Scheduler s(m);
  s.request(menu);
  ASSERT_TRUE(s.active(menu));
  s.take_notifications();
  s.remove_applet(provider);
  EXPECT_FALSE(s.available(ui));
  EXPECT_FALSE(s.active(menu));
  EXPECT_TRUE(s.requested(menu));  // keeps its request
  const auto notes = s.take_notifications();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].kind, Notification::Kind::kRevokedByForce);
  EXPECT_EQ(notes[0].service, ui);
  s.set_available(ui, true);  // not the modules' to bring back
  EXPECT_FALSE(s.available(ui));
  NewApplet again{"UIService2",
                  false,
                  {"UI"},
                  {NewBundle{"io", kPriorityNormal, {{"Monitor", kX}}, std::nullopt}}};
  s.add({{}, {again}});
  EXPECT_TRUE(s.available(ui));
  EXPECT_TRUE(s.active(menu));
  EXPECT_EQ(s.holder(monitor), "UIService2");
}

TEST(Registrar, ProvidingAServiceSomebodyHoldsIsRefused) {
  Base t;
  Scheduler s(t.m);
  s.request(t.low);
  NewApplet p{"P", false, {"S"}, {}};
  EXPECT_THAT(error_of([&] {
                s.add({{}, {p}});
              }),
              HasSubstr("applet 'P' cannot provide service 'S' now: applet 'Low' holds it"));
  s.release(t.low);
  s.add({{}, {p}});
  EXPECT_EQ(s.model().service(t.svc).provider, std::optional<AppletId>(1));
}

TEST(Registrar, ARemovedServiceFreesItsNameAndKeepsItsId) {
  Base t;
  Scheduler s(t.m);
  const auto ids = s.add({{NewService{"T", false, {}}}, {}});
  s.remove_service(ids.services.at(0));
  EXPECT_FALSE(s.model().find_service("T"));
  EXPECT_THAT(error_of([&] { s.remove_service(ids.services.at(0)); }),
              HasSubstr("service 'T' was removed already"));
  const auto again = s.add({{NewService{"T", true, {}}}, {}});
  EXPECT_EQ(again.services.at(0), 2u);
  EXPECT_TRUE(s.model().service(again.services.at(0)).exclusive_only);
}

TEST(Registrar, RemovingAServiceInUseNamesWhatUsesIt) {
  Base t;
  Scheduler s(t.m);
  ModelAddition add;
  add.services.push_back(NewService{"Dock", false, {{"S", kX}}});
  add.services.push_back(NewService{"UI", false, {}});
  add.applets.push_back(NewApplet{"UIService", false, {"UI"}, {}});
  s.add(add);
  EXPECT_THAT(error_of([&] { s.remove_service(t.svc); }),
              HasSubstr("service 'S' cannot be removed while the bundles of applet(s) 'Low' use "
                        "it; service(s) 'Dock' need it (remove them first)"));
  EXPECT_THAT(error_of([&] { s.remove_service(s.model().service_id("UI")); }),
              HasSubstr("applet 'UIService' provides it"));
  s.remove_applet(t.low_applet);
  s.remove_service(s.model().service_id("Dock"));
  s.remove_service(t.svc);  // nothing uses it now
  EXPECT_TRUE(s.model().service(t.svc).removed);
  EXPECT_THAT(error_of([&] {
                s.add({{}, {applet("X", "b", "S", 1)}});
              }),
              HasSubstr("unknown service 'S'"));
}

TEST(Registrar, ARuntimeStartsAnAddedAppletAndEndsARemovedOne) {
  Base t;
  Runtime rt(t.m);
  rt.start();
  std::atomic<int> steps{0};
  std::atomic<bool> used{false};
  AppletCode code;
  code.init = [](AppletContext& ctx) { ctx.request("s"); };
  code.step = [&](AppletContext& ctx) {
    ++steps;
    ctx.use("s", [&] { used = true; });
  };
  code.period = 5ms;
  std::map<std::string, AppletRunner> runners;
  runners["High"] = AppletRunner{code, nullptr};
  rt.add({{}, {applet("High", "s", "S", kPriorityHigh)}}, runners);
  EXPECT_TRUE(eventually([&] { return used.load(); }));
  rt.remove_applet("High");
  const int after = steps.load();
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(steps.load(), after);  // its thread ended
  bool requested = true;
  rt.with_scheduler([&](Scheduler& s) { requested = s.requested(s.model().bundle_id(1, "s")); });
  EXPECT_FALSE(requested);
  EXPECT_THAT(error_of([&] { rt.remove_applet("High"); }), HasSubstr("unknown applet 'High'"));
  EXPECT_THAT(error_of([&] { rt.remove_service("S"); }),
              HasSubstr("the bundles of applet(s) 'Low' use it"));
}

TEST(Registrar, ARemovedAppletWaitingInUseStopsWaiting) {
  Base t;
  Runtime rt(t.m);
  rt.with_scheduler([&](Scheduler& s) { s.request(t.low); });
  std::atomic<bool> returned{false};
  AppletCode code;
  code.init = [](AppletContext& ctx) { ctx.request("s"); };
  code.step = [&](AppletContext& ctx) {
    if (!ctx.use("s", [] {})) returned = true;
  };
  std::map<std::string, AppletRunner> runners;
  runners["Waiter"] = AppletRunner{code, nullptr};
  rt.start();
  const auto ids = rt.add({{}, {applet("Waiter", "s", "S", kPriorityLow)}}, runners);
  const BundleId waiter = t.low + 1;
  ASSERT_EQ(ids.applets.at(0), 1u);
  EXPECT_TRUE(eventually([&] {
    bool asked = false;
    rt.with_scheduler([&](Scheduler& s) { asked = s.requested(waiter); });
    return asked;
  }));
  std::this_thread::sleep_for(20ms);  // into use(), where it waits
  rt.remove_applet("Waiter");         // returns once its thread ended
  EXPECT_TRUE(returned.load());
}

TEST(Registrar, BadRunnersAreRefusedBeforeAnythingIsAdded) {
  Base t;
  Runtime rt(t.m);
  std::map<std::string, AppletRunner> runners;
  runners["Other"] = AppletRunner{AppletCode{}, nullptr};
  EXPECT_THAT(error_of([&] {
                rt.add({{}, {applet("A", "s", "S", 1)}}, runners);
              }),
              HasSubstr("a runner for applet 'Other', which is not added"));
  runners.clear();
  runners["A"] = AppletRunner{};
  EXPECT_THAT(error_of([&] {
                rt.add({{}, {applet("A", "s", "S", 1)}}, runners);
              }),
              HasSubstr("either code or a forward"));
  bool known = true;
  rt.with_scheduler([&](Scheduler& s) { known = s.model().applets().size() > 1; });
  EXPECT_FALSE(known);
}

TEST(Registrar, AnAdditionIsReadFromYamlWithItsLines) {
  Base t;
  const auto loaded = load_addition(t.m,
                                    parse_yaml(R"(services:
  - {name: Dock, depends_on: [S]}
applets:
  - name: Docker
    params: {speed: 3}
    bundles: [{name: d, priority: high, requested: true, resources: [{service: Dock}]}]
)",
                                               "spec"),
                                    "spec");
  ASSERT_EQ(loaded.addition.services.size(), 1u);
  EXPECT_EQ(loaded.addition.services[0].needs.at(0).first, "S");
  ASSERT_EQ(loaded.addition.applets.size(), 1u);
  EXPECT_EQ(loaded.addition.applets[0].bundles.at(0).priority, kPriorityHigh);
  EXPECT_EQ(loaded.applet_params.at("Docker").at("speed"), "3");
  ASSERT_EQ(loaded.requested_at_start.size(), 1u);
  EXPECT_EQ(loaded.requested_at_start[0], std::make_pair(std::string("Docker"), std::string("d")));
  EXPECT_EQ(t.m.services().size(), 1u);  // the model it was checked against is unchanged
  Scheduler s(t.m);
  s.add(loaded.addition);
  EXPECT_EQ(s.model().applet_id("Docker"), 1u);
}

TEST(Registrar, ABadAdditionNamesItsLineAndRule) {
  Base t;
  auto error = [&](const std::string& text) {
    return error_of([&] { load_addition(t.m, parse_yaml(text, "spec"), "spec"); });
  };
  EXPECT_EQ(error("applets:\n  - name: Low\n    bundles: []\n"),
            "spec:2: applet 'Low' is declared twice; names are unique");
  EXPECT_THAT(error("applets:\n  - name: A\n    bundles:\n      - {name: b, resources: "
                    "[{service: Nowhere}]}\n"),
              HasSubstr("spec:4: applet 'A' bundle 'b': unknown service 'Nowhere'"));
  EXPECT_THAT(error("services:\n  - {name: S}\n"),
              HasSubstr("spec:2: service 'S' is declared twice"));
  EXPECT_THAT(error("modules: []\n"), HasSubstr("spec:1: an addition: unknown key 'modules'"));
  EXPECT_THAT(error("{}\n"), HasSubstr("an addition names services: or applets:"));
}

}  // namespace
}  // namespace oscar::applets
