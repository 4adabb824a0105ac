// The applet API: registration, making applets by type, the system file's applet system.
#include "oscar/coordinator/applet.hpp"

#include <unistd.h>

#include <chrono>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/command_types.hpp>
#include <oscar/cue_types.hpp>

#include "oscar/coordinator/applet_system.hpp"
#include "process.hpp"  // tests/common

namespace oscar::coordinator {
namespace {

using ::testing::HasSubstr;

class RecordingGateway final : public AppletGateway {
 public:
  ConfigReply command(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel,
                      const std::string& command, const std::string& type,
                      std::vector<std::uint8_t> cdr) override {
    sent = applet + " " + service + " " + module + "/" + kernel + " " + command + " " + type;
    bytes = cdr.size();
    ConfigReply r;
    r.ok(true);
    return r;
  }
  ConfigReply trigger(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel) override {
    sent = applet + " " + service + " " + module + "/" + kernel + " trigger";
    ConfigReply r;
    r.ok(true);
    return r;
  }
  std::string bundle_name(applets::BundleId) const override { return "b"; }
  std::string sent;
  std::size_t bytes = 0;
};

class Echo final : public Applet {
 public:
  explicit Echo(AppletSetup& setup) : Applet(setup), mode_(setup.param("mode", "full")) {}
  void step(applets::AppletContext&) override {}
  ConfigReply send() {
    SetFrameMode r;
    r.mode(mode_);
    return command("Camera", "cam", "grab", "frame_mode", r);
  }

 private:
  std::string mode_;
};

}  // namespace
}  // namespace oscar::coordinator

OSCAR_REGISTER_APPLET(oscar::coordinator::Echo, "test_echo")

namespace oscar::coordinator {
namespace {

TEST(Applet, ARegisteredTypeIsMadeWithItsNameAndParams) {
  RecordingGateway gateway;
  AppletSetup setup("e", {{"mode", "half"}}, gateway);
  auto applet = make_applet("test_echo", setup, {});
  EXPECT_EQ(applet->name(), "e");
  EXPECT_TRUE(dynamic_cast<Echo&>(*applet).send().ok());
  EXPECT_EQ(gateway.sent, "e Camera cam/grab frame_mode oscar::SetFrameMode");
  EXPECT_GT(gateway.bytes, 0u);
}

TEST(Applet, AnEventAppletsSettlePriorityMustBeAPriority) {
  RecordingGateway gateway;
  AppletSetup good("Menu", {{"settle_priority", "normal"}}, gateway);
  EXPECT_NO_THROW(make_applet("event_applet", good, {}));
  AppletSetup bad("Menu", {{"settle_priority", "urgent"}}, gateway);
  try {
    make_applet("event_applet", bad, {});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("applet 'Menu': settle_priority: "));
    EXPECT_THAT(e.what(), HasSubstr("priority 'urgent' must be low, normal, high, system or a "
                                    "whole number >= 0"));
  }
}

TEST(Applet, AnEventAppletsPeriodIsAWholeNumberOfMilliseconds) {
  RecordingGateway gateway;
  AppletSetup good("Idle", {{"period_ms", "1000"}}, gateway);
  EXPECT_EQ(make_applet("event_applet", good, {})->period(), std::chrono::milliseconds(1000));
  for (const char* bad : {"0", "-5", "1.5", "fast", ""}) {
    AppletSetup setup("Idle", {{"period_ms", bad}}, gateway);
    try {
      make_applet("event_applet", setup, {});
      FAIL() << "no error for '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_THAT(e.what(), HasSubstr(std::string("applet 'Idle': period_ms must be a whole "
                                                  "number of ms >= 1, not '") +
                                      bad + "'"));
    }
  }
}

// Reads the cues of "probe/out" from init() on.
class Watcher final : public Applet {
 public:
  explicit Watcher(AppletSetup& setup) : Applet(setup) {}
  void init(applets::AppletContext&) override {}
  void step(applets::AppletContext&) override {}
  const CueFeed<Bool>& watch() { return cues<Bool>("probe/out"); }
};

TEST(Applet, ReadsTheNewestCueOfAModulesOutput) {
  RecordingGateway gateway;
  DdsParticipant participant(oscar::test::test_domain(), "test:applet-cues");
  AppletSetup setup("w", {}, gateway, &participant);
  Watcher watcher(setup);
  const auto& feed = watcher.watch();
  EXPECT_EQ(feed.address(), "probe/out");
  EXPECT_FALSE(feed.latest());

  // The producer's side as a kernel's output writes it: reliable, with history.
  TopicWriter<Bool, BoolPubSubType> producer(
      participant, topics::cue("probe/out"),
      qos::cue_writer(OutputOptions{.depth = 4, .reliable = true, .transient_local = true}));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (bool value = false; feed.received() < 3 && std::chrono::steady_clock::now() < deadline;
       value = !value) {
    Bool cue;
    cue.value(value);
    producer.write(cue);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_GE(feed.received(), 3u) << "the applet's feed got no cues";
  const auto before = feed.received();
  Bool last;
  last.value(true);
  last.header().seq(4711);
  producer.write(last);
  while (feed.received() == before && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(feed.latest());
  EXPECT_EQ(feed.latest()->header().seq(), 4711u);
}

TEST(Applet, ReadingCuesWhereItDoesNotRunIsAnError) {
  RecordingGateway gateway;
  AppletSetup setup("w", {}, gateway);  // as boot makes applets to check them
  Watcher watcher(setup);
  try {
    watcher.watch();
    FAIL() << "no error";
  } catch (const std::logic_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("applet 'w' reads cues of 'probe/out' where it does not run"));
  }
}

TEST(Applet, AnUnknownTypeIsAnErrorNamingTheFoldersAndTheKnownTypes) {
  RecordingGateway gateway;
  AppletSetup setup("e", {}, gateway);
  try {
    make_applet("tset_echo", setup, {"/nowhere"});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown applet type 'tset_echo': no plugin "
                                    "liboscar_applet_tset_echo.so in [/nowhere]"));
    EXPECT_THAT(e.what(), HasSubstr("test_echo"));
  }
}

constexpr const char* kSystem = R"(system: t
modules:
  - { name: cam, kernels: [ { type: relay, name: grab } ], mode: deactivated }
  - { name: drive, kernels: [ { type: relay, name: pilot } ], mode: deactivated }
services:
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

SystemSpec parse(const std::string& text) { return SystemSpec::parse(YAML::Load(text), "s.yaml"); }

TEST(AppletSystem, HasTheServicesTheirNeedsAndTheApplets) {
  const auto config = applet_system(parse(kSystem));
  const auto& model = config.model;
  const auto camera = model.service_id("Camera");
  EXPECT_TRUE(model.service(camera).exclusive_only);
  ASSERT_EQ(model.service(model.service_id("Pilot")).dependencies.size(), 1u);
  EXPECT_EQ(model.service(model.service_id("Pilot")).dependencies[0].service, camera);
  const auto applet = model.applet_id("switcher");
  EXPECT_EQ(model.bundle(model.bundle_id(applet, "cam")).priority, applets::kPriorityHigh);
  EXPECT_EQ(config.applet_params.at("switcher").at("mode"), "half");
  EXPECT_EQ(config.requested_at_start.size(), 1u);
}

TEST(AppletSystem, AppletBundlesAreCheckedWithTheirLinesInTheSystemFile) {
  std::string text = kSystem;
  const std::string camera = "service: Camera }";
  text.replace(text.find(camera), camera.size(), "service: Light }");
  try {
    applet_system(parse(text));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("s.yaml:17: applet 'switcher' bundle 'cam': unknown service "
                                    "'Light'"));
  }
}

TEST(AppletSystem, CheckAppletsNamesAnAppletWhoseTypeCannotBeMade) {
  std::string text = kSystem;
  text.replace(text.find("frame_mode_switcher"), 19, "frame_mode_swticher");
  try {
    check_applets(parse(text), {"/nowhere"});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("s.yaml:14: applet 'switcher': unknown applet type "
                                    "'frame_mode_swticher'"));
  }
  EXPECT_NO_THROW(check_applets(parse(kSystem), {"/nowhere"}));  // linked into this test
}

TEST(AppletSystem, AnAppletsBadParamsAreAnErrorWhenChecked) {
  std::string text = kSystem;
  text.replace(text.find("{ mode: half }"), 14, "{ modes: '' }");
  EXPECT_THROW(check_applets(parse(text), {}), std::invalid_argument);
}

}  // namespace
}  // namespace oscar::coordinator
