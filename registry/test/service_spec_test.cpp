// The services: and coordinator: sections of a system file (docs/coordinator.md).
#include <algorithm>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/registry/system_spec.hpp"

namespace oscar {
namespace {

using ::testing::HasSubstr;

constexpr const char* kModules = R"(system: t
modules:
  - { name: cam, kernels: [ { type: relay, name: grab } ], mode: deactivated }
  - { name: drive, kernels: [ { type: relay, name: pilot } ], mode: deactivated }
)";

SystemSpec parse(const std::string& rest) {
  return SystemSpec::parse(YAML::Load(std::string(kModules) + rest), "s.yaml");
}

std::string error_of(const std::string& rest) {
  try {
    parse(rest);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

constexpr const char* kGood = R"(services:
  Camera:
    provided_by: [cam/grab]
    access: exclusive
    granted: { activate: "continuous:50ms" }
    idle: deactivate
  Pilot: { provided_by: [drive], needs: [Camera], granted: activate }
coordinator:
  applets:
    - type: frame_mode_switcher
      name: switcher
      params: { mode: half }
      bundles: [ { name: cam, priority: high, resources: [ { service: Camera } ], requested: true } ]
)";

TEST(ServiceSpec, ServicesNameTheirProvidersAccessNeedsAndWhatGrantingAndIdlingMean) {
  const auto s = parse(kGood);
  ASSERT_EQ(s.services.size(), 2u);
  const auto& camera = *s.find_service("Camera");
  ASSERT_EQ(camera.providers.size(), 1u);
  EXPECT_EQ(camera.providers[0].module, "cam");
  EXPECT_EQ(camera.providers[0].kernel, "grab");
  EXPECT_TRUE(camera.exclusive_only);
  EXPECT_EQ(camera.activate, "continuous:50ms");
  EXPECT_TRUE(camera.idle_deactivates);
  const auto& pilot = *s.find_service("Pilot");
  EXPECT_EQ(pilot.providers[0].text(), "drive");
  EXPECT_FALSE(pilot.exclusive_only);
  EXPECT_EQ(pilot.activate, "");  // the kernel's configured mode
  EXPECT_FALSE(pilot.idle_deactivates);
  ASSERT_EQ(pilot.needs.size(), 1u);
  EXPECT_EQ(pilot.needs[0].service, "Camera");
}

TEST(ServiceSpec, ANeedInLongFormGivesItsServiceAndAccess) {
  const auto s = parse(R"(services:
  Camera: { provided_by: [cam] }
  Pilot: { provided_by: [drive], needs: [ { service: Camera, access: shared } ] }
  Dock: { provided_by: [drive], needs: [ { service: Pilot, access: exclusive }, { service: Camera } ] }
coordinator: {}
)");
  const auto& pilot = *s.find_service("Pilot");
  ASSERT_EQ(pilot.needs.size(), 1u);
  EXPECT_EQ(pilot.needs[0].service, "Camera");
  EXPECT_FALSE(pilot.needs[0].exclusive);
  const auto& dock = *s.find_service("Dock");
  ASSERT_EQ(dock.needs.size(), 2u);
  EXPECT_EQ(dock.needs[0].service, "Pilot");
  EXPECT_TRUE(dock.needs[0].exclusive);
  EXPECT_EQ(dock.needs[1].service, "Camera");
  EXPECT_TRUE(dock.needs[1].exclusive);
}

TEST(ServiceSpec, TheCoordinatorBecomesASupervisedModuleOnItsHostWithItsApplets) {
  const auto s = parse(kGood);
  ASSERT_TRUE(s.coordinator);
  EXPECT_EQ(s.coordinator->host, "localhost");
  ASSERT_EQ(s.coordinator->applets.size(), 1u);
  EXPECT_EQ(s.coordinator->applets[0].type, "frame_mode_switcher");
  EXPECT_EQ(s.coordinator->applets[0].name, "switcher");
  const auto* m = s.find_module("coordinator");
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->program, "oscar-coordinator");
  EXPECT_EQ(m->spec.host, "localhost");
  EXPECT_EQ(m->restart.kind, RestartPolicy::Kind::kAuto);
}

TEST(ServiceSpec, AServiceProvidedByAModuleThatDoesNotExistIsAnError) {
  EXPECT_THAT(error_of("services: { Camera: { provided_by: [eye] } }\ncoordinator: {}\n"),
              HasSubstr("s.yaml:5: service 'Camera'.provided_by: no module 'eye' in the system "
                        "(modules: cam, drive)"));
  EXPECT_THAT(
      error_of("services: { Camera: { provided_by: [cam/eye] } }\ncoordinator: {}\n"),
      HasSubstr("s.yaml:5: service 'Camera'.provided_by: module 'cam' has no kernel 'eye'"));
}

TEST(ServiceSpec, ADependencyOnAMissingServiceIsAnError) {
  EXPECT_THAT(
      error_of("services: { Pilot: { provided_by: [drive], needs: [Map] } }\ncoordinator: {}\n"),
      HasSubstr("s.yaml:5: service 'Pilot' needs service 'Map', which is not declared under "
                "services:"));
}

TEST(ServiceSpec, ACycleOfServicesIsAnErrorNamingTheCycle) {
  EXPECT_THAT(error_of(R"(services:
  A: { provided_by: [cam], needs: [B] }
  B: { provided_by: [drive], needs: [C] }
  C: { provided_by: [drive], needs: [A] }
coordinator: {}
)"),
              HasSubstr("s.yaml:6: service 'A': a cycle of needs: A -> B -> C -> A"));
}

TEST(ServiceSpec, UnknownKeysAreErrorsWithTheirLine) {
  EXPECT_THAT(error_of("services:\n  Camera: { provided_by: [cam], acess: shared }\n"
                       "coordinator: {}\n"),
              HasSubstr("s.yaml:6"));
  EXPECT_THAT(error_of("services:\n  Camera: { provided_by: [cam], acess: shared }\n"
                       "coordinator: {}\n"),
              HasSubstr("acess"));
  EXPECT_THAT(error_of("coordinator: { host: localhost, aplets: [] }\n"), HasSubstr("aplets"));
  EXPECT_THAT(error_of("coordinator:\n  applets:\n    - { type: t, name: a, bundels: [] }\n"),
              HasSubstr("s.yaml:7"));
}

TEST(ServiceSpec, AScalarWhereAListBelongsIsAnError) {
  EXPECT_THAT(error_of("services: { Camera: { provided_by: cam } }\ncoordinator: {}\n"),
              HasSubstr("s.yaml:5: service 'Camera'.provided_by must be a list, such as "
                        "[cam, marks/mark_a]"));
  EXPECT_THAT(error_of("services:\n  Camera: { provided_by: [cam] }\n"
                       "  Pilot: { provided_by: [drive], needs: Camera }\ncoordinator: {}\n"),
              HasSubstr("s.yaml:7: service 'Pilot'.needs must be a list, such as [Pilot]"));
  EXPECT_THAT(error_of("coordinator: { applets: { type: t } }\n"),
              HasSubstr("coordinator.applets must be a list"));
}

TEST(ServiceSpec, BadAccessGrantedAndIdleValuesAreErrors) {
  EXPECT_THAT(error_of("services: { C: { provided_by: [cam], access: mine } }\ncoordinator: {}\n"),
              HasSubstr("service 'C'.access 'mine': expected shared or exclusive"));
  EXPECT_THAT(error_of("services: { C: { provided_by: [cam], granted: { activate: often } } }\n"
                       "coordinator: {}\n"),
              HasSubstr("service 'C'.granted.activate: mode 'often'"));
  EXPECT_THAT(
      error_of("services: { C: { provided_by: [cam], idle: sleep } }\ncoordinator: {}\n"),
      HasSubstr("service 'C'.idle 'sleep': expected deactivate, keep or {set: {param: value}}"));
}

TEST(ServiceSpec, GrantingAndIdlingMaySetParametersOfTheProvidersKernels) {
  const auto s = parse(
      "services:\n"
      "  HalfFrames:\n"
      "    provided_by: [cam]\n"
      "    granted: { set: { frame_mode: half, exposure: 3 } }\n"
      "    idle: { set: { frame_mode: quarter } }\n"
      "coordinator: {}\n");
  const auto& svc = s.services.at(0);
  EXPECT_FALSE(svc.activate);
  EXPECT_EQ(svc.granted_params, (ServiceSpec::Params{{"frame_mode", "half"}, {"exposure", "3"}}));
  EXPECT_EQ(svc.idle_params, (ServiceSpec::Params{{"frame_mode", "quarter"}}));
  EXPECT_FALSE(svc.idle_deactivates);

  EXPECT_THAT(error_of("services: { C: { provided_by: [cam], granted: { set: half } } }\n"
                       "coordinator: {}\n"),
              HasSubstr("service 'C'.granted.set: expected a map of parameters such as "
                        "{frame_mode: half}"));
  EXPECT_THAT(error_of("services: { C: { provided_by: [cam], idle: { set: {}, go: 1 } } }\n"
                       "coordinator: {}\n"),
              HasSubstr("go"));
  EXPECT_THAT(error_of("services: { C: { provided_by: [cam], granted: {} } }\ncoordinator: {}\n"),
              HasSubstr("service 'C'.granted: expected {activate: MODE} and/or {set: "));
}

TEST(ServiceSpec, SetParametersNeedOneKernelPerProvider) {
  try {
    SystemSpec::parse(
        YAML::Load("system: t\nmodules: [ { name: cam, kernels: [ { type: relay, name: a },\n"
                   "                          { type: relay, name: b } ] } ]\n"
                   "services: { C: { provided_by: [cam], granted: { set: { x: 1 } } } }\n"
                   "coordinator: {}\n"),
        "s.yaml");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("s.yaml:4: service 'C': set: parameters belong to one "
                                    "kernel, but provider 'cam' has 2 kernels; name the kernel "
                                    "in provided_by (cam/a)"));
  }
}

TEST(ServiceSpec, AKernelsWishesAreBundlesOfAnAppletNamedAfterIt) {
  const auto s = parse(
      "services: { Camera: { provided_by: [cam] } }\n"
      "coordinator:\n"
      "  wishes:\n"
      "    - kernel: drive/pilot\n"
      "      bundles: [ { name: look, priority: low, resources: [ { service: Camera } ] } ]\n");
  ASSERT_EQ(s.coordinator->wishes.size(), 1u);
  const auto& w = s.coordinator->wishes[0];
  EXPECT_EQ(w.applet(), "drive/pilot");
  EXPECT_EQ(w.module, "drive");
  EXPECT_EQ(w.where, "s.yaml:8");
  const std::string head =
      "services: { Camera: { provided_by: [cam] } }\ncoordinator:\n  wishes:\n";
  const std::string bundles = ", bundles: [ { name: look, resources: [ { service: Camera } ] } ]";
  EXPECT_THAT(error_of(head + "    - { kernel: drive" + bundles + " }\n"),
              HasSubstr("s.yaml:8: coordinator.wishes: kernel 'drive' must be module/kernel"));
  EXPECT_THAT(error_of(head + "    - { kernel: drive/wheel" + bundles + " }\n"),
              HasSubstr("s.yaml:8: coordinator.wishes: module 'drive' has no kernel 'wheel'"));
  EXPECT_THAT(error_of(head + "    - { kernel: lamp/lamp" + bundles + " }\n"),
              HasSubstr("coordinator.wishes: no module 'lamp' in the system"));
  EXPECT_THAT(error_of(head + "    - { kernel: drive/pilot }\n"),
              HasSubstr("coordinator.wishes 'drive/pilot': bundles must be a list"));
  EXPECT_THAT(error_of(head + "    - { kernel: drive/pilot" + bundles + " }\n" +
                       "    - { kernel: drive/pilot" + bundles + " }\n"),
              HasSubstr("s.yaml:9: coordinator.wishes 'drive/pilot': the kernel is listed twice"));
  EXPECT_THAT(
      error_of(head + "    - { kernel: drive/pilot, bundles: [ { name: look, requested: true, "
                      "resources: [ { service: Camera } ] } ] }\n"),
      HasSubstr("a wish is asked by its kernel (Wish::ask), not requested at start"));
  EXPECT_THAT(error_of(head + "    - { kernel: drive/pilot" + bundles + ", priority: 3 }\n"),
              HasSubstr("priority"));
}

TEST(ServiceSpec, ServicesNeedACoordinatorAndTheCoordinatorsNameIsReserved) {
  EXPECT_THAT(error_of("services: { C: { provided_by: [cam] } }\n"),
              HasSubstr("services: need a coordinator: section"));
  try {
    SystemSpec::parse(
        YAML::Load("modules: [ { name: coordinator, kernels: [ { type: relay } ] } ]\n"
                   "coordinator: {}\n"),
        "s.yaml");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("a module is named 'coordinator'"));
  }
}

// Seed 000 §5.3: the UI service is provided by the UIService applet, which needs other services.
constexpr const char* kAppletProvided = R"(services:
  UI: { access: exclusive }
  Monitor: { provided_by: [cam], access: exclusive }
coordinator:
  applets:
    - type: event_applet
      name: UIService
      provides: [UI]
      bundles: [ { name: io, priority: system, resources: [ { service: Monitor } ] } ]
)";

TEST(ServiceSpec, AServiceAnAppletProvidesHasNoModules) {
  const auto s = parse(kAppletProvided);
  EXPECT_TRUE(s.find_service("UI")->providers.empty());
  EXPECT_TRUE(s.coordinator->applets[0].node["provides"]);
}

TEST(ServiceSpec, AServiceNobodyProvidesIsAnErrorWithItsLine) {
  EXPECT_THAT(error_of("services: { UI: { access: exclusive } }\ncoordinator: {}\n"),
              HasSubstr("s.yaml:5: service 'UI': nobody provides it: name its modules in "
                        "provided_by, or list it under an applet's provides:"));
}

TEST(ServiceSpec, AServiceHasOneKindOfProviderAndOneProvidingApplet) {
  EXPECT_THAT(error_of(R"(services: { Monitor: { provided_by: [cam] } }
coordinator:
  applets: [ { type: t, name: A, provides: [Monitor] } ]
)"),
              HasSubstr("s.yaml:7: applet 'A' provides service 'Monitor', which modules provide "
                        "already (provided_by at s.yaml:5)"));
  EXPECT_THAT(error_of(R"(services: { UI: {} }
coordinator:
  applets: [ { type: t, name: A, provides: [UI] }, { type: t, name: B, provides: [UI] } ]
)"),
              HasSubstr("s.yaml:7: service 'UI' is provided by two applets, 'A' and 'B'"));
  EXPECT_THAT(error_of(R"(services: { UI: {} }
coordinator:
  applets: [ { type: t, name: A, provides: [Screen] } ]
)"),
              HasSubstr("applet 'A' provides service 'Screen', which is not declared"));
  EXPECT_THAT(error_of(R"(services: { UI: {} }
coordinator:
  applets: [ { type: t, name: A, provides: UI } ]
)"),
              HasSubstr("applet 'A'.provides must be a list, such as [UI]"));
}

TEST(ServiceSpec, TheCoordinatorsHostMustBeDeclared) {
  EXPECT_THAT(error_of("coordinator: { host: mars }\n"),
              HasSubstr("s.yaml:5: coordinator: unknown host 'mars'"));
}

}  // namespace
}  // namespace oscar

namespace oscar {
namespace {

constexpr const char* kRemote = R"(services: { Camera: { provided_by: [cam] } }
coordinator:
  applet_lease: 2s
  applets:
    - { type: t, name: a, process: helpers }
    - { type: t, name: b, process: helpers }
    - { type: t, name: c }
)";

TEST(ServiceSpec, AnAppletWithAProcessRunsInAModuleOfItsOwnProgramOscarApplet) {
  const auto s = parse(kRemote);
  ASSERT_TRUE(s.coordinator);
  EXPECT_EQ(s.coordinator->applet_lease, std::chrono::milliseconds(2000));
  ASSERT_EQ(s.coordinator->applets.size(), 3u);
  EXPECT_EQ(s.coordinator->applets[0].process, "helpers");
  EXPECT_EQ(s.coordinator->applets[0].host, "localhost");  // the coordinator's
  EXPECT_TRUE(s.coordinator->applets[1].remote());
  EXPECT_FALSE(s.coordinator->applets[2].remote());
  const auto* m = s.find_module("helpers");
  ASSERT_NE(m, nullptr);  // one process for both applets
  EXPECT_EQ(m->program, "oscar-applet");
  EXPECT_EQ(m->spec.host, "localhost");
  EXPECT_EQ(m->restart.kind, RestartPolicy::Kind::kAuto);
  EXPECT_EQ(std::count_if(s.modules.begin(), s.modules.end(),
                          [](const SystemModule& x) { return x.program == "oscar-applet"; }),
            1);
  // host: alone names a process of its own on that host.
  const auto h = parse("coordinator: { applets: [ { type: t, name: a, host: localhost } ] }\n");
  EXPECT_EQ(h.coordinator->applets[0].process, "applets_localhost");
  EXPECT_NE(h.find_module("applets_localhost"), nullptr);
  // Without either key the applet runs in the coordinator.
  EXPECT_EQ(parse(kGood).coordinator->applet_lease, std::chrono::milliseconds(1500));
}

TEST(ServiceSpec, BadAppletProcessesAndLeasesAreErrorsWithTheirLine) {
  EXPECT_THAT(error_of("coordinator: { applets: [ { type: t, name: a, proces: p } ] }\n"),
              HasSubstr("s.yaml:5"));
  EXPECT_THAT(error_of("coordinator: { applets: [ { type: t, name: a, proces: p } ] }\n"),
              HasSubstr("proces"));
  EXPECT_THAT(error_of("coordinator: { applets: [ { type: t, name: a, host: mars } ] }\n"),
              HasSubstr("s.yaml:5: applet 'a': unknown host 'mars' (hosts: localhost)"));
  EXPECT_THAT(error_of("coordinator: { applets: [ { type: t, name: a, process: cam } ] }\n"),
              HasSubstr("s.yaml:5: applet 'a'.process: 'cam' is a module of the system"));
  EXPECT_THAT(error_of("coordinator: { applets: [ { type: t, name: a, process: grab } ] }\n"),
              HasSubstr("applet 'a'.process: 'grab' is a kernel's name"));
  EXPECT_THAT(
      error_of("coordinator: { applets: [ { type: t, name: a, process: coordinator } ] }\n"),
      HasSubstr("applet 'a'.process: 'coordinator' is the coordinator's own process"));
  EXPECT_THAT(
      error_of("coordinator: { applets: [ { type: t, name: a, process: 'x/y' } ] }\n"),
      HasSubstr("applet 'a'.process 'x/y': a process name is a module name, an identifier"));
  EXPECT_THAT(error_of("coordinator: { applet_lease: soon }\n"),
              HasSubstr("s.yaml:5: coordinator.applet_lease:"));
  EXPECT_THAT(error_of("coordinator: { applet_lease: 0ms }\n"),
              HasSubstr("coordinator.applet_lease: must be positive"));
  EXPECT_THAT(error_of("coordinator: { aplet_lease: 1s }\n"), HasSubstr("aplet_lease"));
}

TEST(ServiceSpec, AProcessOfAppletsHasOneHost) {
  const auto e = [] {
    try {
      SystemSpec::parse(YAML::Load(R"(system: t
hosts: { a: { local: true }, b: { netns: nb } }
modules:
  - { name: cam, host: a, kernels: [ { type: relay, name: grab } ] }
coordinator:
  host: a
  applets:
    - { type: t, name: x, process: p }
    - { type: t, name: y, process: p, host: b }
)"),
                        "s.yaml");
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  }();
  EXPECT_THAT(e, HasSubstr("s.yaml:9: applet 'y': process 'p' runs on host 'a'"));
}

}  // namespace
}  // namespace oscar

namespace oscar {
namespace {

std::string addition_error(const SystemSpec& s, const std::string& text) {
  try {
    s.parse_addition(YAML::Load(text), "add.yaml", s.services);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(SystemAddition, ServicesAndAppletsAreReadAsInTheSystemFile) {
  const auto s = parse(kGood);
  const auto add = s.parse_addition(YAML::Load(R"(services:
  Nav: { provided_by: [drive/pilot], needs: [Pilot], granted: { activate: "continuous:20ms" } }
  Plan: {}
applets:
  - { type: event_applet, name: navigator, provides: [Plan],
      bundles: [ { name: go, resources: [ { service: Nav } ] } ] }
)"),
                                    "add.yaml", s.services);
  ASSERT_EQ(add.services.size(), 2u);
  EXPECT_EQ(add.services[0].name, "Nav");
  EXPECT_EQ(add.services[0].providers.at(0).text(), "drive/pilot");
  EXPECT_EQ(add.services[0].needs.at(0).service, "Pilot");
  EXPECT_EQ(add.services[0].activate, std::optional<std::string>("continuous:20ms"));
  EXPECT_EQ(add.services[0].where, "add.yaml:2");
  ASSERT_EQ(add.applets.size(), 1u);
  EXPECT_EQ(add.applets[0].type, "event_applet");
  EXPECT_EQ(add.applets[0].where, "add.yaml:5");
  EXPECT_FALSE(add.applets[0].remote());
}

TEST(SystemAddition, BadAdditionsAreErrorsWithTheirLineInTheAddition) {
  const auto s = parse(kGood);
  EXPECT_EQ(addition_error(s, "services:\n  Camera: { provided_by: [cam] }\n"),
            "add.yaml:2: duplicate service 'Camera'");
  EXPECT_THAT(addition_error(s, "services:\n  X:\n    provided_by: [nowhere]\n"),
              HasSubstr("add.yaml:3: service 'X'.provided_by: no module 'nowhere' in the system"));
  EXPECT_THAT(addition_error(s, "services:\n  X: { provided_by: [cam], needs: [Y] }\n"),
              HasSubstr("add.yaml:2: service 'X' needs service 'Y', which is not declared"));
  EXPECT_THAT(addition_error(s, "services:\n  X: {}\n"),
              HasSubstr("add.yaml:2: service 'X': nobody provides it"));
  EXPECT_THAT(addition_error(s, "applets:\n  - { type: t, name: a, provides: [Camera] }\n"),
              HasSubstr("add.yaml:2: applet 'a' provides service 'Camera', which modules provide"));
  EXPECT_THAT(addition_error(s, "applets:\n  - { type: t, name: a, colour: red }\n"),
              HasSubstr("add.yaml:2: applet: unknown key 'colour'"));
  EXPECT_THAT(addition_error(s, "modules: []\n"), HasSubstr("unknown key 'modules'"));
  EXPECT_THAT(addition_error(s, "{}\n"), HasSubstr("names services: or applets:"));
}

}  // namespace
}  // namespace oscar
