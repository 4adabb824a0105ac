// Kernel failures are counted, shown and acted on (on_kernel_error), and repeated log lines are
// held back with a count.
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>

#include "oscar/module.hpp"
#include "oscar/testing/eventually.hpp"
#include "repeat_filter_sink.hpp"
#include "test_kernels.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using testing::HasSubstr;

std::unique_ptr<Module> module_with(const std::string& policy, const std::string& params = "") {
  const auto yaml = fmt::format(R"(
name: flaky
mode: {{ continuous: 2ms }}
{}
kernels: [ {{ type: test_failing, name: cam, params: {{ {} }} }} ]
)",
                                policy.empty() ? "" : "on_kernel_error: " + policy, params);
  auto m = std::make_unique<Module>(ModuleSpec::from_yaml(YAML::Load(yaml), "test.yaml"),
                                    std::vector<std::string>{});
  m->start(-1);
  return m;
}

KernelState cam(const Module& m) { return m.state().kernels().at(0); }

TEST(KernelErrors, ContinueCountsEveryFailureAndKeepsCallingTheKernel) {
  auto m = module_with("{ action: continue, after: 1 }");
  ASSERT_TRUE(eventually([&] { return cam(*m).failures() >= 20; }));
  EXPECT_EQ(cam(*m).mode(), "continuous");
  EXPECT_EQ(cam(*m).last_failure(), "process(): sensor unplugged");
  EXPECT_EQ(m->exit_reason(), "");
}

TEST(KernelErrors, DeactivateTakesTheKernelOutAfterTheFailuresInARow) {
  auto m = module_with("{ action: deactivate, after: 3 }");
  ASSERT_TRUE(eventually([&] { return cam(*m).mode() == "deactivated"; }));
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(cam(*m).failures(), 3u) << "it ran on after being deactivated";
  EXPECT_THAT(m->state().last_transition(),
              HasSubstr("cam: continuous(2ms) -> deactivated (failed 3 times in a row; "
                        "on_kernel_error: deactivate)"));
}

TEST(KernelErrors, ACallThatReturnsStartsTheCountAgain) {
  // Fails twice, succeeds once, and so on: never three failures in a row.
  auto m = module_with("{ action: deactivate, after: 3 }", "succeed_every: 3");
  ASSERT_TRUE(eventually([&] { return cam(*m).failures() >= 30; }));
  EXPECT_EQ(cam(*m).mode(), "continuous");
}

TEST(KernelErrors, RestartIsTheDefaultAndStopsTheModuleNamingTheKernel) {
  auto m = module_with("");
  std::thread waiter([&] { m->wait(); });
  waiter.join();  // returns once the policy asked the module to stop
  EXPECT_EQ(m->exit_reason(),
            "kernel 'cam' failed 3 times in a row (on_kernel_error: restart); last: process(): "
            "sensor unplugged");
  EXPECT_GE(cam(*m).failures(), 3u);
}

TEST(KernelErrors, AKernelThatThrowsOnlyInOnActivateIsCountedAndActedOnToo) {
  auto m = module_with("{ action: deactivate, after: 2 }", "fail_in: on_activate");
  ASSERT_TRUE(eventually([&] { return cam(*m).mode() == "deactivated"; }));
  EXPECT_EQ(cam(*m).failures(), 2u);
  EXPECT_EQ(cam(*m).last_failure(), "on_activate(): sensor unplugged");
  EXPECT_EQ(dynamic_cast<test::Failing&>(m->kernel("cam").kernel()).activations_, 2);
  EXPECT_EQ(dynamic_cast<test::Failing&>(m->kernel("cam").kernel()).calls_, 0)
      << "process() ran without a successful on_activate()";
}

TEST(KernelErrors, BadPoliciesAreRefusedWithTheLineAndTheRule) {
  const auto refused = [](const std::string& policy) {
    try {
      ModuleSpec::from_yaml(YAML::Load("name: m\non_kernel_error: " + policy +
                                       "\nkernels: [ { type: test_failing, name: k } ]"),
                            "m.yaml");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused("explode"),
            "m.yaml:2: on_kernel_error: unknown action 'explode' (allowed: continue, deactivate, "
            "restart)");
  EXPECT_THAT(refused("{ action: restart, after: 0 }"), HasSubstr("after: 0 must be at least 1"));
  EXPECT_THAT(refused("{ action: restart, every: 2 }"),
              HasSubstr("unknown key 'every' (allowed: action, after)"));
}

spdlog::details::log_msg line(spdlog::log_clock::time_point at, const char* logger,
                              const char* text) {
  return spdlog::details::log_msg(at, spdlog::source_loc{}, logger, spdlog::level::err, text);
}

TEST(RepeatFilterSink, ShowsARepeatedLineOncePerWindowWithHowOftenItCame) {
  auto shown = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(100);
  shown->set_pattern("[%n] %v");
  internal::RepeatFilterSink filter(1s);
  filter.add_sink(shown);
  const auto t0 = spdlog::log_clock::now();
  // 50 failures at 10 Hz of one kernel, interleaved with another's.
  for (int i = 0; i < 50; ++i) {
    filter.log(line(t0 + i * 100ms, "m/cam", "camera missing"));
    if (i % 10 == 0) filter.log(line(t0 + i * 100ms + 1ms, "m/imu", "imu missing"));
  }
  const auto lines = shown->last_formatted();
  ASSERT_EQ(lines.size(), 10u);
  EXPECT_EQ(lines[0], "[m/cam] camera missing\n");
  EXPECT_EQ(lines[1], "[m/imu] imu missing\n");
  EXPECT_EQ(lines[2], "[m/cam] camera missing (9 more times in the last 1.0 s)\n");
  EXPECT_EQ(lines[3], "[m/imu] imu missing\n");
}

}  // namespace
}  // namespace oscar
