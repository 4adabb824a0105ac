#include "bench_source_kernel.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <oscar/harness.hpp>
#include <oscar/testing/conformance.hpp>

namespace oscar::modules {
namespace {

OSCAR_KERNEL_CONFORMANCE_TEST(BenchSourceBool, "bench_source", "{type: Bool}")
OSCAR_KERNEL_CONFORMANCE_TEST(BenchSourceImage, "bench_source", "{type: GvImage, dx: 64, dy: 48}")

TEST(BenchSource, PublishesTheSeedSizes) {
  KernelHarness lines("bench_source", YAML::Load("{type: LineSeg3DSeq}"));
  lines.step();
  const auto l = lines.take<LineSeg3DSeq>("out");
  ASSERT_EQ(l.size(), 1u);
  EXPECT_EQ(l[0]->lines().size() * 6 * sizeof(double), 4800u);

  KernelHarness image("bench_source", YAML::Load("{type: GvImage}"));
  image.step();
  const auto i = image.take<GvImage>("out");
  ASSERT_EQ(i.size(), 1u);
  EXPECT_EQ(i[0]->image().size(), 442368u);
  EXPECT_EQ(i[0]->dx(), 768);
  EXPECT_EQ(i[0]->dy(), 576);
}

TEST(BenchSource, NumbersAndStampsEveryCueAndStopsAfterCount) {
  KernelHarness h("bench_source", YAML::Load("{type: Bool, count: 2}"), "src");
  for (int i = 0; i < 4; ++i) {
    h.step();
    h.advance(std::chrono::milliseconds(10));
  }
  const auto out = h.take<Bool>("out");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0]->header().seq(), 1u);
  EXPECT_EQ(out[1]->header().seq(), 2u);
  EXPECT_EQ(out[1]->header().stamps().at(0) - out[0]->header().stamps().at(0), 10'000'000u);
  EXPECT_EQ(out[0]->header().source(), "src/out");
}

}  // namespace
}  // namespace oscar::modules
