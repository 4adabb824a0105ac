#include "oscar/registry/clock_estimator.hpp"

#include <gtest/gtest.h>

namespace oscar {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

// A probe from a host whose clock is `offset` ahead of the registry's, sent at registry time
// `sent`, `out` on the way there, `held` at the registry and `back` on the way back.
ClockProbeStamps probe(milliseconds offset, milliseconds sent, milliseconds out, milliseconds held,
                       milliseconds back) {
  const auto t2 = sent + out;
  const auto t3 = t2 + held;
  return {.t1 = sent + offset, .t2 = t2, .t3 = t3, .t4 = t3 + back + offset};
}

TEST(ClockEstimator, HasNoEstimateBeforeTheFirstSample) {
  EXPECT_FALSE(ClockEstimator{}.estimate().has_value());
}

TEST(ClockEstimator, SymmetricDelaysGiveTheExactOffset) {
  ClockEstimator e;
  const auto s = e.add(probe(milliseconds(250), milliseconds(1000), milliseconds(3),
                             milliseconds(1), milliseconds(3)));
  ASSERT_TRUE(s);
  EXPECT_EQ(s->offset, milliseconds(250));
  EXPECT_EQ(s->round_trip, milliseconds(6));  // the registry's millisecond is not counted
  const auto est = e.estimate();
  ASSERT_TRUE(est);
  EXPECT_EQ(est->offset, milliseconds(250));
  EXPECT_EQ(est->uncertainty, milliseconds(3));
  EXPECT_EQ(est->samples, 1u);
}

TEST(ClockEstimator, AsymmetricDelaysStayWithinTheUncertainty) {
  ClockEstimator e;
  e.add(
      probe(milliseconds(-40), milliseconds(0), milliseconds(9), milliseconds(0), milliseconds(1)));
  const auto est = e.estimate();
  ASSERT_TRUE(est);
  // 9 ms out, 1 ms back: the estimate is off by half the difference, which the uncertainty
  // (half the round trip) covers.
  EXPECT_EQ(est->offset, milliseconds(-44));
  EXPECT_EQ(est->uncertainty, milliseconds(5));
  EXPECT_LE(std::chrono::abs(est->offset - milliseconds(-40)), est->uncertainty);
}

TEST(ClockEstimator, PicksTheSampleWithTheSmallestRoundTrip) {
  ClockEstimator e;
  e.add(probe(milliseconds(100), milliseconds(0), milliseconds(30), milliseconds(0),
              milliseconds(2)));
  e.add(probe(milliseconds(100), milliseconds(1000), milliseconds(1), milliseconds(0),
              milliseconds(2)));
  e.add(probe(milliseconds(100), milliseconds(2000), milliseconds(2), milliseconds(5),
              milliseconds(20)));
  const auto est = e.estimate();
  ASSERT_TRUE(est);
  EXPECT_EQ(est->offset, nanoseconds(milliseconds(100)) + nanoseconds(500'000));  // (2 - 1) / 2
  EXPECT_EQ(est->uncertainty, nanoseconds(1'500'000));
  EXPECT_EQ(est->samples, 3u);
}

TEST(ClockEstimator, ForgetsSamplesOlderThanTheWindow) {
  ClockEstimator e;
  // The best sample first (offset 7 ms), then kWindow worse ones (offset 0): it drops out.
  e.add(probe(milliseconds(7), milliseconds(0), milliseconds(0), milliseconds(0), milliseconds(0)));
  for (std::size_t i = 0; i < ClockEstimator::kWindow - 1; ++i) {
    e.add(probe(milliseconds(0), milliseconds(1000 * (static_cast<long>(i) + 1)), milliseconds(4),
                milliseconds(0), milliseconds(4)));
  }
  EXPECT_EQ(e.estimate()->offset, milliseconds(7));  // still in the window of 16
  EXPECT_EQ(e.estimate()->samples, ClockEstimator::kWindow);
  e.add(probe(milliseconds(0), milliseconds(99'000), milliseconds(4), milliseconds(0),
              milliseconds(4)));
  EXPECT_EQ(e.estimate()->offset, milliseconds(0));
  EXPECT_EQ(e.estimate()->uncertainty, milliseconds(4));
  EXPECT_EQ(e.estimate()->samples, ClockEstimator::kWindow);
}

TEST(ClockEstimator, RejectsAProbeWithANegativeRoundTrip) {
  ClockEstimator e;
  // The host's clock was stepped back while the probe was out: t4 before t1.
  EXPECT_FALSE(e.add({.t1 = milliseconds(100),
                      .t2 = milliseconds(50),
                      .t3 = milliseconds(51),
                      .t4 = milliseconds(90)}));
  EXPECT_FALSE(e.estimate().has_value());
}

}  // namespace
}  // namespace oscar
