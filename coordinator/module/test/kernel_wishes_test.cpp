// Kernels' resource wishes at the coordinator (seed 004 §2.4): what a module sends on
// oscar/sched/wishes is requested and released for the kernel's applet "module/kernel", the plan
// grants it or gives it to a higher priority (and the kernel yields at once), and the plan tells
// the module which wishes are granted.
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/coordinator/coordinator.hpp"
#include "oscar/testing/eventually.hpp"
#include "process.hpp"  // tests/common

namespace oscar::coordinator {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr const char* kSystem = R"(
system: s
modules:
  - name: cam
    kernels: [ { type: framegrabber, name: cam } ]
  - name: det
    kernels: [ { type: apriltag_detect, name: det } ]
services:
  HalfFrames: { provided_by: [cam], access: exclusive }
coordinator:
  applets:
    - { type: test_idle, name: mission,
        bundles: [ { name: look, priority: high, resources: [ { service: HalfFrames } ] } ] }
  wishes:
    - kernel: det/det
      bundles: [ { name: closer_look, priority: low, resources: [ { service: HalfFrames } ] } ]
)";

SchedModuleWishes wishes(unsigned long incarnation, unsigned long long seq,
                         std::vector<std::string> asked) {
  SchedModuleWishes w;
  w.module_name("det");
  w.incarnation(incarnation);
  w.seq(seq);
  SchedKernelWish k;
  k.kernel("det");
  k.asked(std::move(asked));
  w.kernels().push_back(k);
  return w;
}

class Wishes : public ::testing::Test {
 protected:
  Wishes()
      : system_(SystemSpec::parse(YAML::Load(kSystem), "s.yaml")),
        participant_(oscar::test::test_domain(), "test:wishes"),
        coordinator_(system_, participant_, {}),
        module_(participant_, topics::sched_wishes()) {
    coordinator_.start();
  }

  // The HalfFrames holders and the kernel's granted wishes, once they are `holders` and
  // `granted`.
  bool plan_shows(const std::vector<std::string>& holders,
                  const std::vector<std::string>& granted) {
    return eventually(
        [&] {
          const auto p = coordinator_.plan();
          std::vector<std::string> g{"(no entry)"};
          for (const auto& a : p.applets()) {
            if (a.name() == "det/det") g = a.granted();
          }
          return p.services().at(0).holders() == holders && g == granted;
        },
        std::chrono::seconds(10));
  }

  SystemSpec system_;
  DdsParticipant participant_;
  Coordinator coordinator_;
  TopicWriter<SchedModuleWishes, SchedModuleWishesPubSubType> module_;
};

TEST_F(Wishes, AKernelsWishIsGrantedByThePlanAndYieldsToAHigherPriority) {
  ASSERT_TRUE(plan_shows({}, {}));
  module_.write(wishes(1, 1, {"closer_look"}));
  ASSERT_TRUE(plan_shows({"det/det"}, {"closer_look"}));
  const auto plan = coordinator_.plan();  // kept: a range over a temporary's member dangles
  for (const auto& a : plan.applets()) {
    if (a.name() == "det/det") {
      EXPECT_EQ(a.process(), "det") << "a kernel's wishes run in its module";
    }
  }
  // The mission asks with a higher priority: the kernel hands the camera over at once.
  AppletEvent e;
  e.applet("mission");
  e.bundle("look");
  e.event("request");
  ASSERT_FALSE(coordinator_.apply_event(e));
  ASSERT_TRUE(plan_shows({"mission"}, {}));
  e.event("release");
  ASSERT_FALSE(coordinator_.apply_event(e));
  ASSERT_TRUE(plan_shows({"det/det"}, {"closer_look"})) << "still wished: granted again";
  // The kernel drops it.
  module_.write(wishes(1, 2, {}));
  ASSERT_TRUE(plan_shows({}, {}));
}

TEST_F(Wishes, AnOlderSetIsIgnoredAndANewStartReplacesTheOldOnes) {
  module_.write(wishes(1, 5, {"closer_look"}));
  ASSERT_TRUE(plan_shows({"det/det"}, {"closer_look"}));
  module_.write(wishes(1, 4, {}));  // late, from before
  module_.write(wishes(0, 9, {}));  // an earlier start of the module
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_TRUE(plan_shows({"det/det"}, {"closer_look"}));
  module_.write(wishes(2, 1, {}));  // the module restarted and wishes nothing yet
  ASSERT_TRUE(plan_shows({}, {}));
}

TEST_F(Wishes, AnOperatorsEventForAKernelsWishesIsRefused) {
  AppletEvent e;
  e.applet("det/det");
  e.bundle("closer_look");
  e.event("request");
  const auto error = coordinator_.apply_event(e);
  ASSERT_TRUE(error);
  EXPECT_EQ(*error, "'det/det' is a kernel's wishes: its kernel asks for them and drops them");
}

}  // namespace
}  // namespace oscar::coordinator
