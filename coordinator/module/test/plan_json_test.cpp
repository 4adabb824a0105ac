#include "oscar/coordinator/plan_json.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar::coordinator {
namespace {

AppletPlan two_services() {
  AppletPlan plan;
  ServicePlan camera;
  camera.name("Camera");
  camera.access("exclusive");
  camera.holders({"high"});
  camera.waiting({"low"});
  camera.available(true);
  camera.plan("high");
  ServicePlan pilot;
  pilot.name("Pilot");
  pilot.access("shared");
  pilot.available(false);
  pilot.plan("unavailable");
  plan.services({camera, pilot});
  AppletEntry a;
  a.name("high");
  a.process("coordinator");
  a.state("holding");
  plan.applets({a});
  return plan;
}

TEST(PlanJson, ServicesWithHoldersAccessWaitingAndPlanThenApplets) {
  EXPECT_EQ(plan_json(two_services()),
            R"({"services":{"Camera":{"holders":["high"],"access":"exclusive","waiting":["low"],)"
            R"("plan":"high"},)"
            R"("Pilot":{"holders":[],"access":"shared","waiting":[],"plan":"unavailable",)"
            R"("available":false}},)"
            R"("applets":[{"name":"high","process":"coordinator","state":"holding"}]})");
}

TEST(PlanJson, TheTableShowsAnUnavailableServiceAndWhoWaits) {
  const auto table = plan_table(two_services());
  EXPECT_THAT(table, ::testing::HasSubstr("Camera               exclusive  high"));
  EXPECT_THAT(table, ::testing::HasSubstr("low"));
  EXPECT_THAT(table, ::testing::HasSubstr("(unavailable)"));
  EXPECT_THAT(table, ::testing::HasSubstr("coordinator    holding"));
}

}  // namespace
}  // namespace oscar::coordinator
