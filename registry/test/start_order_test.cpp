// At boot a consumer is launched only after the producers of its inputs (start_order.hpp).
#include "start_order.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/cue_types.hpp"

namespace oscar::internal {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

SystemSpec parse(const std::string& yaml) { return SystemSpec::parse(YAML::Load(yaml), "s.yaml"); }

TEST(StartOrder, AConsumerListedBeforeItsProducersWaitsForBoth) {
  const auto s = parse(R"(
system: t
modules:
  - name: sink
    kernels: [ { type: bench_sink, name: sink, inputs: { in: fwd/out } } ]
  - name: relay
    kernels: [ { type: relay, name: fwd, inputs: { in: src/out } } ]
  - name: src
    kernels: [ { type: bench_source, name: src } ]
)");
  const auto first = producers_launched_first(s);
  ASSERT_EQ(first.size(), 3u);
  EXPECT_THAT(first[0], ElementsAre(1u));  // sink after the relay
  EXPECT_THAT(first[1], ElementsAre(2u));  // the relay after the source
  EXPECT_THAT(first[2], IsEmpty());
}

TEST(StartOrder, InACycleTheModuleListedFirstStartsFirst) {
  const auto s = parse(R"(
system: t
modules:
  - name: a
    kernels: [ { type: relay, name: a, inputs: { in: b/out } } ]
  - name: b
    kernels: [ { type: relay, name: b, inputs: { in: a/out } } ]
  - name: c
    kernels: [ { type: bench_sink, name: c, inputs: { in: b/out } } ]
)");
  const auto first = producers_launched_first(s);
  EXPECT_THAT(first[0], IsEmpty()) << "a waits for nobody: b reads a";
  EXPECT_THAT(first[1], ElementsAre(0u));
  EXPECT_THAT(first[2], ElementsAre(1u));
}

TEST(StartOrder, WiresBetweenAModulesOwnKernelsAreNoReasonToWait) {
  const auto s = parse(R"(
system: t
modules:
  - name: pair
    kernels:
      - { type: bench_source, name: src }
      - { type: bench_sink, name: sink, inputs: { in: src/out } }
)");
  EXPECT_THAT(producers_launched_first(s)[0], IsEmpty());
}

}  // namespace
}  // namespace oscar::internal
