#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/cue_types.hpp>
#include <oscar/harness.hpp>
#include <oscar/idl_texts.hpp>
#include <oscar/testing/conformance.hpp>

#include "blinker_rhythm.hpp"

OSCAR_KERNEL_CONFORMANCE_TEST(Blinker, "blinker", "{period: 3}")

TEST(Blinker, TogglesEveryPeriodCycles) {
  oscar::KernelHarness h("blinker", YAML::Load("{period: 2}"));
  for (int i = 0; i < 6; ++i) h.step();
  std::vector<bool> values;
  for (const auto& cue : h.take<oscar::Bool>("light")) values.push_back(cue->value());
  EXPECT_EQ(values, (std::vector<bool>{true, true, false, false, true, true}));
}

TEST(Blinker, PublishesItsRhythmInATypeOfItsOwnWhoseIdlItBrings) {
  oscar::KernelHarness h("blinker", YAML::Load("{period: 2}"));
  for (int i = 0; i < 3; ++i) h.step();
  const auto rhythm = h.take<blinker::Rhythm>("rhythm");
  ASSERT_EQ(rhythm.size(), 3u);
  EXPECT_EQ(rhythm[2]->period(), 2);
  EXPECT_FALSE(rhythm[2]->on());
  const auto idl = oscar::find_idl_text("blinker::Rhythm");
  ASSERT_TRUE(idl) << "the plugin registers its IDL text when loaded";
  EXPECT_THAT(*idl, ::testing::HasSubstr("module blinker"));
  EXPECT_THAT(*idl, ::testing::HasSubstr("struct CueHeader")) << "OSCAR's header flattened in";
}
