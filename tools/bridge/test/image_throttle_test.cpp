#include "image_throttle.hpp"

#include <gtest/gtest.h>

namespace oscar::bridge {
namespace {

constexpr std::uint64_t kMs = 1'000'000;

TEST(ImageThrottle, LetsThroughAtMostTheRatePerChannelAndCountsTheRest) {
  ImageThrottle throttle(10);  // 100 ms apart, 90 ms with the jitter allowance
  int passed = 0;
  for (std::uint64_t t = 0; t < 1000 * kMs; t += 33 * kMs) passed += throttle.admit(1, t);
  EXPECT_EQ(passed, 11);  // 0, 99, 198, ... 990 ms: every third image of a 30 Hz camera
  EXPECT_EQ(throttle.held_back().at(1), 31u - 11u);
  EXPECT_TRUE(throttle.admit(2, 33 * kMs)) << "each channel has its own rate";
}

TEST(ImageThrottle, ToleratesJitterOfARateAtTheLimit) {
  ImageThrottle throttle(30);
  int passed = 0;
  // A 30 Hz camera whose images come 31 and 35 ms apart in turn.
  std::uint64_t t = 0;
  for (int i = 0; i < 30; ++i) {
    passed += throttle.admit(1, t);
    t += (i % 2 == 0 ? 31 : 35) * kMs;
  }
  EXPECT_EQ(passed, 30);
}

TEST(ImageThrottle, WithoutALimitEverythingPassesAndForgetStartsAfresh) {
  ImageThrottle none(0);
  EXPECT_FALSE(none.limits());
  EXPECT_TRUE(none.admit(1, 0));
  EXPECT_TRUE(none.admit(1, 1));
  ImageThrottle throttle(1);
  EXPECT_TRUE(throttle.admit(1, 0));
  EXPECT_FALSE(throttle.admit(1, 10 * kMs));
  throttle.forget(1);
  EXPECT_TRUE(throttle.admit(1, 20 * kMs)) << "a new subscription gets its first image at once";
}

TEST(ImageThrottle, KnowsTheImageSchemas) {
  EXPECT_TRUE(is_image_schema("oscar::GvImage"));
  EXPECT_TRUE(is_image_schema("oscar::PlainGvImage"));
  EXPECT_TRUE(is_image_schema("foxglove.RawImage"));
  EXPECT_FALSE(is_image_schema("oscar::Bool"));
  EXPECT_FALSE(is_image_schema("foxglove.SceneUpdate"));
}

}  // namespace
}  // namespace oscar::bridge
