#include "oscar/applets/model.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_support.hpp"

#include <stdexcept>

namespace oscar::applets {
namespace {

using ::testing::HasSubstr;

using testing::error_of;

TEST(Model, UnknownServiceIsNamed) {
  Model m;
  m.add_service("Pilot");
  EXPECT_THAT(error_of([&] { m.service_id("Pilott"); }), HasSubstr("unknown service 'Pilott'"));
}

TEST(Model, DuplicateServiceIsRejected) {
  Model m;
  m.add_service("Pilot");
  EXPECT_THAT(error_of([&] { m.add_service("Pilot"); }),
              HasSubstr("service 'Pilot' is declared twice"));
}

TEST(Model, SharedAccessToExclusiveOnlyServiceIsRejected) {
  Model m;
  const ServiceId ui = m.add_service("UI", true);
  const AppletId a = m.add_applet("Menu");
  EXPECT_THAT(error_of([&] {
                m.add_bundle(a, "ui", {{ui, Access::kShared}});
              }),
              HasSubstr("shared access to exclusive-only service 'UI'"));
}

TEST(Model, ServiceTwiceInOneBundleIsRejected) {
  Model m;
  const ServiceId p = m.add_service("Pilot");
  const AppletId a = m.add_applet("A");
  EXPECT_THAT(error_of([&] {
                m.add_bundle(a, "b", {{p, Access::kShared}, {p, Access::kExclusive}});
              }),
              HasSubstr("lists service 'Pilot' twice"));
}

TEST(Model, SecondProviderIsRejected) {
  Model m;
  const ServiceId ui = m.add_service("UI");
  m.provide(m.add_applet("A"), ui);
  const AppletId b = m.add_applet("B");
  EXPECT_THAT(error_of([&] { m.provide(b, ui); }), HasSubstr("already provided by applet 'A'"));
}

TEST(Model, NeedsListsDependenciesAndProviderResources) {
  Model m;
  const ServiceId pilot = m.add_service("Pilot");
  const ServiceId dock = m.add_service("Dock");
  m.add_dependency(dock, pilot);
  const ServiceId monitor = m.add_service("Monitor");
  const ServiceId ui = m.add_service("UI");
  const AppletId uia = m.add_applet("UIService");
  m.provide(uia, ui);
  m.add_bundle(uia, "io", {{monitor, Access::kExclusive}});
  ASSERT_EQ(m.needs(dock).size(), 1u);
  EXPECT_EQ(m.needs(dock)[0].service, pilot);
  EXPECT_EQ(m.needs(dock)[0].by, Use::By::kService);
  ASSERT_EQ(m.needs(ui).size(), 1u);
  EXPECT_EQ(m.needs(ui)[0].service, monitor);
  EXPECT_EQ(m.needs(ui)[0].by, Use::By::kResource);
  EXPECT_TRUE(m.needs(pilot).empty());
}

TEST(Model, CycleOfTwoServiceAppletsIsFound) {
  testing::TwoServiceApplets t;
  Model& m = t.m;
  const ServiceId s1 = t.s1;
  const AppletId a = t.a;
  const AppletId b = t.b;
  const BundleId ba = m.add_bundle(a, "x", {{t.s2, Access::kShared}});
  const BundleId bb = m.add_bundle(b, "x", {{s1, Access::kShared}});
  const AppletId c = m.add_applet("C");
  const BundleId bc = m.add_bundle(c, "x", {{s1, Access::kShared}});
  EXPECT_EQ(m.cycle_of(ba), (std::vector<BundleId>{ba, bb}));
  EXPECT_EQ(m.cycle_of(bb), (std::vector<BundleId>{ba, bb}));
  EXPECT_TRUE(m.cycle_of(bc).empty());
}

}  // namespace
}  // namespace oscar::applets
