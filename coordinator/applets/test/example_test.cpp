// The usage example of README.md, compiled and checked (README code is cut from here).
#include <gtest/gtest.h>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {
namespace {

TEST(Example, ReadmeDockingControllerAndPilot) {
  // README-BEGIN
  Model m;
  const ServiceId pilot = m.add_service("Pilot");
  const ServiceId dock = m.add_service("DockingController");
  m.add_dependency(dock, pilot);  // known only from configuration (seed Abb. 4.10)
  const BundleId drive =
      m.add_bundle(m.add_applet("DriveTo"), "task", {{pilot, Access::kExclusive}});
  const BundleId charge =
      m.add_bundle(m.add_applet("Battery"), "charge", {{dock, Access::kExclusive}}, kPriorityHigh);
  Scheduler s(m);  // logical clock at 0 ms, revoke_wait 5 s
  s.request(drive);
  s.request(charge);  // a conflict of second degree: Battery wins
  // s.holder(dock) == "Battery", s.holder(pilot) == "blocked" (the controller drives it)
  // DriveTo was told (kRevokeRequested, new holder Battery) and still drives until it yields:
  s.yield(drive);  // or: s.advance_to(5000ms) revokes by force
  // s.active(charge) == true
  // README-END
  EXPECT_EQ(s.holder(dock), "Battery");
  EXPECT_EQ(s.holder(pilot), "blocked");
  EXPECT_TRUE(s.active(charge));
  EXPECT_FALSE(s.active(drive));
}

}  // namespace
}  // namespace oscar::applets
