#include "relay_kernel.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/harness.hpp>
#include <oscar/testing/conformance.hpp>

namespace oscar::modules {
namespace {

OSCAR_KERNEL_CONFORMANCE_TEST(RelayBool, "relay", "{type: Bool}")
OSCAR_KERNEL_CONFORMANCE_TEST(RelayLines, "relay", "{type: LineSeg3DSeq}")
OSCAR_KERNEL_CONFORMANCE_TEST(RelayImage, "relay", "{type: GvImage}")

TEST(Relay, ForwardsEveryCueAndAppendsItsStamp) {
  KernelHarness h("relay", YAML::Load("{type: LineSeg3DSeq}"), "fuse");
  for (int i = 1; i <= 3; ++i) {
    LineSeg3DSeq cue;
    cue.header().seq(i);
    append_stamp(cue.header(), 100 * i);
    cue.lines().resize(static_cast<std::size_t>(i));
    h.feed("in", cue);
  }
  h.set_now(5000);
  h.step();
  const auto out = h.take<LineSeg3DSeq>("out");
  ASSERT_EQ(out.size(), 3u);
  for (int i = 1; i <= 3; ++i) {
    const auto& cue = *out[static_cast<std::size_t>(i - 1)];
    EXPECT_THAT(cue.header().stamps(), testing::ElementsAre(100u * i, 5000u));
    EXPECT_EQ(cue.header().source(), "fuse/out");
    EXPECT_EQ(cue.header().seq(), static_cast<unsigned long long>(i))
        << "the relay numbers its own";
    EXPECT_EQ(cue.lines().size(), static_cast<std::size_t>(i));
  }
  h.step();
  EXPECT_TRUE(h.take<LineSeg3DSeq>("out").empty()) << "each cue is forwarded once";
}

TEST(Relay, StubPublishesAFusedLookingCue) {
  KernelHarness h("relay", YAML::Load("{type: Bool}"));
  h.step_stub();
  const auto out = h.take<Bool>("out");
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0]->header().stamps().size(), 2u);
}

TEST(Relay, RejectsAnUnknownType) {
  EXPECT_THAT([] { KernelHarness h("relay", YAML::Load("{type: Image}")); },
              testing::ThrowsMessage<std::invalid_argument>(testing::HasSubstr(
                  "parameter 'type' = 'Image' is not one of: Bool, LineSeg3DSeq, GvImage")));
}

}  // namespace
}  // namespace oscar::modules
