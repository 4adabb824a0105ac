#include <unistd.h>

#include <cstdlib>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <oscar/harness.hpp>
#include <oscar/module.hpp>
#include <oscar/perception_types.hpp>
#include <oscar/testing/conformance.hpp>

#include <oscar/testing/eventually.hpp>
#include "../sequencer_kernel.hpp"

namespace oscar {
namespace {
using ::testing::HasSubstr;
using namespace std::chrono_literals;

// A module with a framegrabber that runs only when triggered, on a DDS domain of this test.
class Cameras : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = 1 + static_cast<int>(getpid() % 200);
    setenv("OSCAR_DOMAIN", std::to_string(domain_).c_str(), 1);
    module_ = std::make_unique<Module>(ModuleSpec::from_yaml(YAML::Load(R"(
name: cams
kernels: [ { type: framegrabber, name: cam, params: { source: synthetic } } ]
mode: { single_step: { trigger: command } }
)"),
                                                             "test"),
                                       std::vector<std::string>{});
    module_->start(domain_);
  }
  void TearDown() override { module_->stop(); }

  std::uint64_t frames() {
    return module_->kernel("cam").ports().find_output("frame")->published();
  }
  // Through the module's state: it reads parameters under the frame's lock, while set_param
  // changes them on the module's own threads.
  std::string frame_mode() {
    const auto state = module_->state();  // kept: a range-for would not extend its life
    for (const auto& k : state.kernels()) {
      if (k.name() == "cam") return YAML::Load(k.params())["frame_mode"].as<std::string>();
    }
    return "";
  }
  // Commands go out asynchronously: a failure is reported by a later cycle.
  static std::string first_error(KernelHarness& seq) {
    for (int i = 0; i < 100; ++i) {
      try {
        seq.step();
      } catch (const std::exception& e) {
        return e.what();
      }
      std::this_thread::sleep_for(50ms);
    }
    return "no error";
  }

  int domain_ = 0;
  std::unique_ptr<Module> module_;
};

TEST_F(Cameras, TriggersTheListedKernelsEachCycle) {
  KernelHarness seq("sequencer", YAML::Load("{steps: 'cams:cam'}"), "control");
  for (int i = 1; i <= 3; ++i) {
    EXPECT_TRUE(eventually([&] { return frames() == static_cast<std::uint64_t>(i - 1); }));
    seq.step();
    EXPECT_TRUE(eventually([&] { return frames() == static_cast<std::uint64_t>(i); }))
        << "cycle " << i << ": " << frames() << " frames";
  }
}

TEST_F(Cameras, SetsTheFrameModeByConfigurationAndFollowsItsSchedule) {
  KernelHarness seq(
      "sequencer",
      YAML::Load("{framegrabbers: 'cams:cam', frame_mode_schedule: 'quarter:1,half:2'}"),
      "control");
  auto& sequencer = dynamic_cast<modules::Sequencer&>(seq.kernel());
  // Each step waits until the last one's commands are through: a step that finds them still
  // on their way is skipped (and the schedule moves on with the cycle count).
  const auto step = [&] {
    ASSERT_TRUE(eventually([&] { return sequencer.idle(); }));
    seq.step();
  };
  step();
  EXPECT_TRUE(eventually([&] { return frame_mode() == "quarter"; })) << frame_mode();
  step();
  EXPECT_TRUE(eventually([&] { return frame_mode() == "half"; })) << frame_mode();
  step();
  step();  // the schedule repeats
  EXPECT_TRUE(eventually([&] { return frame_mode() == "quarter"; })) << frame_mode();
}

TEST_F(Cameras, AModuleThatIsNotRunningIsAClearError) {
  KernelHarness seq("sequencer", YAML::Load("{steps: 'ghost:cam', timeout: 300ms}"), "control");
  const auto error = first_error(seq);
  EXPECT_THAT(error, HasSubstr("sequencer: triggering ghost/cam failed"));
  EXPECT_THAT(error, HasSubstr("no module named 'ghost' is running"));
}

TEST_F(Cameras, AKernelThatCannotBeTriggeredIsAClearError) {
  KernelHarness seq("sequencer", YAML::Load("{steps: 'cams:nope'}"), "control");
  const auto error = first_error(seq);
  EXPECT_THAT(error, HasSubstr("sequencer: triggering cams/nope failed"));
  EXPECT_THAT(error, HasSubstr("has no kernel 'nope'"));
}

TEST(Sequencer, BadParametersAreRefused) {
  const auto refused = [](const std::string& yaml) {
    try {
      KernelHarness h("sequencer", YAML::Load(yaml));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(refused("{steps: 'cam'}"), HasSubstr("'cam' is not 'module:kernel'"));
  EXPECT_THAT(refused("{frame_mode: half}"), HasSubstr("needs 'framegrabbers'"));
  EXPECT_THAT(refused("{framegrabbers: 'm:k', frame_mode_schedule: 'half'}"),
              HasSubstr("'half' is not 'full|half|quarter:<cycles>'"));
  EXPECT_THAT(refused("{frame_mode: eighth}"), HasSubstr("frame_mode"));
}

}  // namespace
}  // namespace oscar

OSCAR_KERNEL_CONFORMANCE_TEST(Sequencer, "sequencer", "{}")
