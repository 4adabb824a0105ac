// CobraControl (coordinator/module/applets/cobra_control.cpp) on the applet scheduler's runtime,
// with a gateway that records what it would send to the modules: while it holds its cameras it
// triggers them in order every cycle and sets their frame mode by its schedule; released, it
// stops; a refused trigger ends that cycle's sequence.
#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/command_types.hpp>

#include "oscar/applets/runtime.hpp"
#include "oscar/coordinator/applet.hpp"
#include "oscar/coordinator/applet_system.hpp"
#include "oscar/testing/eventually.hpp"

namespace oscar::coordinator {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr const char* kSystem = R"(
system: s
modules:
  - name: landmarks
    kernels: [ { type: framegrabber, name: cam_a }, { type: framegrabber, name: cam_b } ]
services:
  CameraA: { provided_by: [landmarks/cam_a], access: exclusive }
  CameraB: { provided_by: [landmarks/cam_b], access: exclusive }
coordinator:
  applets:
    - type: cobra_control
      name: cobra
      params: { cameras: 'CameraA:landmarks/cam_a, CameraB:landmarks/cam_b', cycle_ms: 20,
                frame_modes: 'half:2,quarter:1' }
      bundles: [ { name: cameras, resources: [ { service: CameraA }, { service: CameraB } ] } ]
)";

// What the applet sends, in order: "trigger landmarks/cam_a", "frame_mode landmarks/cam_b half".
class Recorder final : public AppletGateway {
 public:
  ConfigReply command(const std::string&, const std::string&, const std::string& module,
                      const std::string& kernel, const std::string& command,
                      const std::string& type, std::vector<std::uint8_t> cdr) override {
    EXPECT_EQ(type, "oscar::SetFrameMode");
    const auto request =
        std::static_pointer_cast<SetFrameMode>(idl_type_info<SetFrameMode>().deserialize(cdr));
    return add(command + " " + module + "/" + kernel + " " + request->mode());
  }
  ConfigReply trigger(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel) override {
    EXPECT_EQ(applet, "cobra");
    EXPECT_EQ(service, kernel == "cam_a" ? "CameraA" : "CameraB");
    if (slow_first_.exchange(false)) std::this_thread::sleep_for(std::chrono::milliseconds(300));
    return add("trigger " + module + "/" + kernel);
  }
  std::string bundle_name(applets::BundleId) const override { return "cameras"; }

  std::vector<std::string> sent() {
    std::lock_guard lock(mutex_);
    return sent_;
  }
  void refuse(const std::string& what) {
    std::lock_guard lock(mutex_);
    refused_ = what;
  }
  // The first trigger takes 300 ms (as the first one waits until DDS has found the module).
  void slow_first() { slow_first_ = true; }
  // When each of sent() was answered.
  std::vector<std::chrono::steady_clock::time_point> times() {
    std::lock_guard lock(mutex_);
    return times_;
  }

 private:
  ConfigReply add(const std::string& what) {
    std::lock_guard lock(mutex_);
    sent_.push_back(what);
    times_.push_back(std::chrono::steady_clock::now());
    ConfigReply r;
    r.ok(what != refused_);
    if (!r.ok()) r.error("refused by the test");
    return r;
  }
  std::mutex mutex_;
  std::vector<std::string> sent_;
  std::vector<std::chrono::steady_clock::time_point> times_;
  std::string refused_;
  std::atomic<bool> slow_first_ = false;
};

// The applet from kSystem (with `params` replaced if given) running on a runtime of its own.
class Running {
 public:
  explicit Running(std::string system = kSystem)
      : config_(applet_system(SystemSpec::parse(YAML::Load(system), "s.yaml"))),
        runtime_(config_.model, config_.options) {
    AppletSetup setup("cobra", config_.applet_params.at("cobra"), recorder);
    applet_ = make_applet("cobra_control", setup, {});
    applets::AppletCode code;
    code.step = [this](applets::AppletContext& ctx) { applet_->step(ctx); };
    code.period = applet_->period();
    runtime_.set_code("cobra", std::move(code));
    runtime_.start();
  }
  ~Running() { runtime_.stop(); }
  void event(bool request) {
    runtime_.with_scheduler([&](applets::Scheduler& s) {
      const auto& m = s.model();
      const auto b = m.bundle_id(m.applet_id("cobra"), "cameras");
      request ? s.request(b) : s.release(b);
    });
  }
  Recorder recorder;

 private:
  applets::SystemConfig config_;
  applets::Runtime runtime_;
  std::unique_ptr<Applet> applet_;
};

TEST(CobraControl, TriggersItsCamerasInOrderEveryCycleAndSwitchesTheFrameModeByItsSchedule) {
  Running r;
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(r.recorder.sent().empty()) << "nothing before it holds the cameras";
  r.event(true);
  ASSERT_TRUE(eventually([&] { return r.recorder.sent().size() >= 16; }));
  const auto sent = r.recorder.sent();
  // Cycles 0 and 1 half frames, cycle 2 quarter, cycle 3 half again: the mode is set when it
  // changes, before that cycle's triggers.
  const std::vector<std::string> expected = {"frame_mode landmarks/cam_a half",
                                             "frame_mode landmarks/cam_b half",
                                             "trigger landmarks/cam_a",
                                             "trigger landmarks/cam_b",
                                             "trigger landmarks/cam_a",
                                             "trigger landmarks/cam_b",
                                             "frame_mode landmarks/cam_a quarter",
                                             "frame_mode landmarks/cam_b quarter",
                                             "trigger landmarks/cam_a",
                                             "trigger landmarks/cam_b",
                                             "frame_mode landmarks/cam_a half",
                                             "frame_mode landmarks/cam_b half",
                                             "trigger landmarks/cam_a",
                                             "trigger landmarks/cam_b",
                                             "trigger landmarks/cam_a",
                                             "trigger landmarks/cam_b"};
  EXPECT_EQ(std::vector<std::string>(sent.begin(), sent.begin() + 16), expected);

  // Released, it stops sequencing (a cycle already under way may finish).
  r.event(false);
  const auto at_release = r.recorder.sent().size();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // ten cycles
  EXPECT_LE(r.recorder.sent().size(), at_release + 4);
  const auto stopped = r.recorder.sent().size();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(r.recorder.sent().size(), stopped);

  // Granted again, it starts afresh: the first mode of the schedule, then the triggers.
  r.event(true);
  ASSERT_TRUE(eventually([&] { return r.recorder.sent().size() >= stopped + 4; }));
  const auto again = r.recorder.sent();
  EXPECT_THAT(std::vector<std::string>(again.begin() + stopped, again.begin() + stopped + 4),
              ElementsAre("frame_mode landmarks/cam_a half", "frame_mode landmarks/cam_b half",
                          "trigger landmarks/cam_a", "trigger landmarks/cam_b"));
}

TEST(CobraControl, ARefusedTriggerEndsTheCyclesSequence) {
  Running r;
  r.recorder.refuse("trigger landmarks/cam_a");
  r.event(true);
  ASSERT_TRUE(eventually([&] {
    const auto s = r.recorder.sent();
    return std::count(s.begin(), s.end(), "trigger landmarks/cam_a") >= 3;
  }));
  const auto sent = r.recorder.sent();
  EXPECT_EQ(std::count(sent.begin(), sent.end(), "trigger landmarks/cam_b"), 0)
      << "B is never triggered before A";
}

// A camera triggered again before its last image went through its chain takes both triggers
// as one and falls a frame behind the other (the fused pose is then 8 mm off the ground truth,
// measured): after a cycle that overran, the steps that are due at once are skipped, and the
// next cycle starts at least half a cycle (10 ms) after the overrun one ended.
TEST(CobraControl, AfterACycleThatOverranTheNextStartsHalfACycleAfterItsEndAtTheEarliest) {
  Running r;
  r.recorder.slow_first();
  r.event(true);
  ASSERT_TRUE(eventually([&] { return r.recorder.sent().size() >= 6; }));
  const auto sent = r.recorder.sent();
  const auto times = r.recorder.times();
  ASSERT_EQ(sent[2], "trigger landmarks/cam_a");  // the slow one, after the two frame modes
  ASSERT_EQ(sent[3], "trigger landmarks/cam_b");  // the end of the cycle that overran
  ASSERT_EQ(sent[4], "trigger landmarks/cam_a");
  EXPECT_GE(times[4] - times[3], std::chrono::milliseconds(10))
      << "the next cycle came right after the one that overran";
}

// config/landmarks-2hosts.yaml: one camera per module (one module per host); each cycle
// triggers both, side by side.
constexpr const char* kTwoModules = R"(
system: s
modules:
  - name: landmarks
    kernels: [ { type: framegrabber, name: cam_a } ]
  - name: cameras_b
    kernels: [ { type: framegrabber, name: cam_b } ]
services:
  CameraA: { provided_by: [landmarks/cam_a], access: exclusive }
  CameraB: { provided_by: [cameras_b/cam_b], access: exclusive }
coordinator:
  applets:
    - type: cobra_control
      name: cobra
      params: { cameras: 'CameraB:cameras_b/cam_b, CameraA:landmarks/cam_a', cycle_ms: 20 }
      bundles: [ { name: cameras, resources: [ { service: CameraA }, { service: CameraB } ] } ]
)";

TEST(CobraControl, TriggersTheCamerasOfDifferentModulesEveryCycle) {
  Running r(kTwoModules);
  r.event(true);
  const auto count = [](const std::vector<std::string>& s, const char* what) {
    return std::count(s.begin(), s.end(), what);
  };
  ASSERT_TRUE(eventually([&] { return count(r.recorder.sent(), "trigger cameras_b/cam_b") >= 5; }));
  r.event(false);
  ASSERT_TRUE(eventually([&] {
    const auto s = r.recorder.sent();
    return count(s, "trigger cameras_b/cam_b") == count(s, "trigger landmarks/cam_a");
  })) << "both cameras in every cycle";
  const auto s = r.recorder.sent();
  EXPECT_EQ(count(s, "trigger cameras_b/cam_b") + count(s, "trigger landmarks/cam_a"),
            static_cast<long>(s.size()))
      << "no frame mode: frame_modes is not set";
}

std::string with_params(const std::string& params) {
  std::string text = kSystem;
  const auto from = text.find("params:"), to = text.find("bundles:");
  return text.replace(from, to - from, "params: " + params + "\n      ");
}

TEST(CobraControl, BadParamsAreErrorsNamingTheAppletAndTheRule) {
  const auto error = [](const std::string& params) -> std::string {
    try {
      Running r(with_params(params));
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_THAT(error("{ frame_modes: full }"), HasSubstr("applet 'cobra': cameras is empty"));
  EXPECT_THAT(error("{ cameras: 'landmarks/cam_a' }"),
              HasSubstr("applet 'cobra': cameras: 'landmarks/cam_a' is not "
                        "'<service>:<module>/<kernel>'"));
  EXPECT_THAT(error("{ cameras: 'A:m/k', cycle_ms: 0 }"), HasSubstr("cycle_ms must be > 0"));
  EXPECT_THAT(error("{ cameras: 'A:m/k', cycle_ms: fast }"),
              HasSubstr("cycle_ms: 'fast' is not a number"));
  EXPECT_THAT(error("{ cameras: 'A:m/k', frame_modes: 'eighth' }"),
              HasSubstr("frame_modes: 'eighth' is not 'full|half|quarter[:<cycles>]'"));
  EXPECT_THAT(error("{ cameras: 'A:m/k', frame_modes: 'half,quarter:5' }"),
              HasSubstr("several modes take turns: each needs its cycles"));
}

}  // namespace
}  // namespace oscar::coordinator
