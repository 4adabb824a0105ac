// The out-of-tree blinker in a system booted by the installed OSCAR (oscar_add_system_test).
#include <gtest/gtest.h>
#include <oscar/cue_types.hpp>
#include <oscar/testing/booted_system.hpp>

using BlinkerSystem = oscar::testing::BootedSystem;

TEST_F(BlinkerSystem, BlinksThroughARelayAndStopsWhenDeactivated) {
  boot();
  ASSERT_TRUE(wait_until_running({"blinker", "relayed"}));
  ASSERT_TRUE(wait_for_cues({"blink/light", "relay/out"}));
  const auto lights = read_cues<oscar::Bool>("blink/light", 8);
  ASSERT_EQ(lights.size(), 8u);
  int changes = 0;
  for (std::size_t i = 1; i < lights.size(); ++i)
    changes += lights[i].value() != lights[i - 1].value() ? 1 : 0;
  EXPECT_GE(changes, 2) << "period 2: it toggles every other cycle";
  const auto relayed = read_cues<oscar::Bool>("relay/out", 2);
  ASSERT_EQ(relayed.size(), 2u);
  EXPECT_EQ(relayed[0].header().stamps().size(), 2u) << "the blinker's stamp and the relay's";

  const auto reply = configure("blinker", oscar::CMD_SET_PARAM, {"blink", "period", "0"});
  EXPECT_FALSE(reply.ok()) << "period 0 is below the parameter's range";
  const auto off = configure("blinker", oscar::CMD_DEACTIVATE, {"blink"});
  ASSERT_TRUE(off.ok()) << off.error();
  EXPECT_EQ(off.state().kernels()[0].mode(), "deactivated");
}
