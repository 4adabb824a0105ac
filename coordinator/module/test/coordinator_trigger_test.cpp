// The coordinator's gateway for an applet's trigger (Coordinator::trigger): refused, with the
// holder's name, unless the applet holds the service and the kernel provides it.
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/coordinator/coordinator.hpp"
#include "process.hpp"  // tests/common

namespace oscar::coordinator {
namespace {

using ::testing::HasSubstr;

// An applet that only holds what it is granted.
class Idle final : public Applet {
 public:
  explicit Idle(AppletSetup& setup) : Applet(setup) {}
  void step(applets::AppletContext&) override {}
};

}  // namespace
}  // namespace oscar::coordinator

OSCAR_REGISTER_APPLET(oscar::coordinator::Idle, "test_idle")

namespace oscar::coordinator {
namespace {

constexpr const char* kSystem = R"(
system: s
modules:
  - name: cam
    kernels: [ { type: framegrabber, name: cam } ]
services:
  Camera: { provided_by: [cam], access: exclusive }
coordinator:
  applets:
    - { type: test_idle, name: holder, bundles: [ { name: camera, resources: [ { service: Camera } ] } ] }
    - { type: test_idle, name: other, bundles: [ { name: camera, resources: [ { service: Camera } ] } ] }
)";

TEST(Coordinator, AnAppletsTriggerIsRefusedNamingTheHolderUnlessItHoldsTheService) {
  const auto system = SystemSpec::parse(YAML::Load(kSystem), "s.yaml");
  DdsParticipant participant(oscar::test::test_domain(), "test:coordinator");
  Coordinator c(system, participant, {});
  c.start();

  auto reply = c.trigger("holder", "Camera", "cam", "cam");
  EXPECT_FALSE(reply.ok());
  EXPECT_EQ(reply.error(), "applet 'holder' does not hold service 'Camera': nobody holds it now");

  AppletEvent request;
  request.applet("holder");
  request.bundle("camera");
  request.event("request");
  ASSERT_FALSE(c.apply_event(request));
  reply = c.trigger("other", "Camera", "cam", "cam");
  EXPECT_FALSE(reply.ok());
  EXPECT_EQ(reply.error(), "applet 'other' does not hold service 'Camera': it is held by 'holder'");

  reply = c.trigger("holder", "Camera", "lamp", "lamp");
  EXPECT_FALSE(reply.ok());
  EXPECT_THAT(reply.error(),
              HasSubstr("lamp/lamp does not provide service 'Camera' (its providers: cam)"));
  reply = c.trigger("holder", "Light", "cam", "cam");
  EXPECT_FALSE(reply.ok());
  EXPECT_EQ(reply.error(), "no service 'Light' in the system");
  c.stop();
}

}  // namespace
}  // namespace oscar::coordinator
