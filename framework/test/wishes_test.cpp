// Resource wishes (docs/kernels.md, "Resource wishes"): the declaration, and the frame's side
// on the wire — the module sends its active kernels' asked wishes on oscar/sched/wishes and reads
// which are granted from the coordinator's plan.
#include <unistd.h>

#include <mutex>
#include <optional>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/module.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "process.hpp"  // tests/common
#include "test_kernels.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using testing::HasSubstr;

TEST(Wishes, AreDeclaredOnceByIdentifierAndAskedOnlyOnceUntilDropped) {
  KernelPorts ports("k");
  KernelSetup setup("k", "wishing", ports);
  const auto error_of = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no error";
  };
  auto& half = setup.wish("half_frames");
  EXPECT_EQ(error_of([&] { setup.wish("half_frames"); }),
            "kernel 'k' (wishing): wish 'half_frames' is declared twice; wish names are unique "
            "per kernel");
  EXPECT_THAT(error_of([&] { setup.wish("half frames"); }),
              HasSubstr("wish name 'half frames' must be an identifier"));
  int changes = 0;
  half.on_change([&] { ++changes; });
  half.ask();
  half.ask();
  EXPECT_TRUE(half.asked());
  EXPECT_EQ(changes, 1) << "asking again is no change";
  half.set_granted(true);
  EXPECT_TRUE(half.granted());
  half.drop();
  EXPECT_FALSE(half.granted()) << "a dropped wish is not granted, whatever the plan said last";
  EXPECT_EQ(changes, 2);
  half.on_change({});
  half.ask();
  EXPECT_EQ(changes, 2) << "called after it was detached";
}

// What the module sent last, as the coordinator reads it.
class CoordinatorSide {
 public:
  explicit CoordinatorSide(DdsParticipant& p)
      : reader_(p, topics::sched_wishes(),
                [this](const SchedModuleWishes& w, const auto&) {
                  std::lock_guard lock(mutex_);
                  last_ = w;
                }),
        plan_(p, topics::applet_plan()) {}

  // "kernel:wish,wish;..." of the last set, or "(none)".
  std::string asked() {
    std::lock_guard lock(mutex_);
    if (!last_) return "(none)";
    std::string out;
    for (const auto& k : last_->kernels()) {
      out += k.kernel() + ":";
      for (const auto& a : k.asked()) out += a + ",";
      out += ";";
    }
    return out;
  }
  void grant(const std::string& applet, std::vector<std::string> bundles) {
    AppletPlan p;
    AppletEntry e;
    e.name(applet);
    e.granted(std::move(bundles));
    p.applets().push_back(e);
    plan_.write(p);
  }

 private:
  std::mutex mutex_;
  std::optional<SchedModuleWishes> last_;
  TopicReader<SchedModuleWishes, SchedModuleWishesPubSubType> reader_;
  TopicWriter<AppletPlan, AppletPlanPubSubType> plan_;
};

ConfigCommand configure(CommandKind kind, const std::string& kernel) {
  ConfigCommand c;
  c.id(1);
  c.sender("coordinator");
  c.kind(kind);
  c.args({kernel});
  return c;
}

TEST(Wishes, TheModuleSendsWhatItsActiveKernelsAskAndHearsWhatThePlanGrants) {
  const int domain = oscar::test::test_domain();
  DdsParticipant p(domain, "test:coordinator");
  CoordinatorSide coordinator(p);
  Module m(ModuleSpec::from_yaml(YAML::Load(R"(
name: eye
mode: { continuous: 5ms }
kernels: [ { type: test_wisher, name: look_out }, { type: test_counter, name: quiet } ]
)"),
                                 "test.yaml"),
           {});
  m.start(domain);
  auto& wish = dynamic_cast<test::Wisher&>(m.kernel("look_out").kernel()).look_;
  ASSERT_TRUE(eventually([&] { return coordinator.asked() == "look_out:look,;"; }, 10s))
      << coordinator.asked();
  EXPECT_FALSE(wish.granted());
  coordinator.grant("eye/look_out", {"look"});
  ASSERT_TRUE(eventually([&] { return wish.granted(); }, 10s)) << "the plan's grant never arrived";
  coordinator.grant("other/look_out", {"look"});  // another module's kernel of the same name
  ASSERT_TRUE(eventually([&] { return !wish.granted(); }, 10s));
  // Deactivated, the kernel wishes nothing; activated again, what it still asks counts again.
  ASSERT_TRUE(m.apply(configure(CMD_DEACTIVATE, "look_out")).ok());
  ASSERT_TRUE(eventually([&] { return coordinator.asked() == ""; }, 10s)) << coordinator.asked();
  ASSERT_TRUE(m.apply(configure(CMD_ACTIVATE, "look_out")).ok());
  ASSERT_TRUE(eventually([&] { return coordinator.asked() == "look_out:look,;"; }, 10s))
      << coordinator.asked();
  m.stop();
}

}  // namespace
}  // namespace oscar
