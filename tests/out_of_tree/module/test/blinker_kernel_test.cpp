#include <gtest/gtest.h>
#include <oscar/cue_types.hpp>
#include <oscar/harness.hpp>
#include <oscar/testing/conformance.hpp>

OSCAR_KERNEL_CONFORMANCE_TEST(Blinker, "blinker", "{period: 3}")

TEST(Blinker, TogglesEveryPeriodCycles) {
  oscar::KernelHarness h("blinker", YAML::Load("{period: 2}"));
  for (int i = 0; i < 6; ++i) h.step();
  std::vector<bool> values;
  for (const auto& cue : h.take<oscar::Bool>("light")) values.push_back(cue->value());
  EXPECT_EQ(values, (std::vector<bool>{true, true, false, false, true, true}));
}
