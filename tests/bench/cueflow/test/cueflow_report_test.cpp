// The arithmetic of `oscar bench cueflow` (cueflow_report.hpp and peer_common.hpp), no timing.
#include <gtest/gtest.h>

#include "cueflow_report.hpp"
#include "peers/peer_common.hpp"

namespace oscar::bench {
namespace {

TEST(CueflowReport, ParsesAReportWithP99) {
  const auto l = parse_report(nlohmann::json::parse(
      R"({"type":"Bool","samples":1000,"delivery_us":{"p50":10.5,"p90":20,"p99":30,"max":90}})"));
  EXPECT_DOUBLE_EQ(l.p50, 10.5);
  EXPECT_DOUBLE_EQ(l.p90, 20);
  EXPECT_DOUBLE_EQ(l.p99, 30);
  EXPECT_DOUBLE_EQ(l.max, 90);
  EXPECT_EQ(l.samples, 1000);
}

TEST(CueflowReport, ReadsAReportWithoutP99AsZero) {
  const auto l = parse_report(
      nlohmann::json::parse(R"({"samples":5,"delivery_us":{"p50":1,"p90":2,"max":3}})"));
  EXPECT_DOUBLE_EQ(l.p99, 0);
}

TEST(CueflowReport, MediansEachFigureOverRunsAndSumsSamples) {
  const auto m =
      median_of({{5, 50, 500, 5000, 10}, {1, 10, 100, 1000, 10}, {3, 30, 300, 3000, 10}});
  EXPECT_DOUBLE_EQ(m.p50, 3);
  EXPECT_DOUBLE_EQ(m.p90, 30);
  EXPECT_DOUBLE_EQ(m.p99, 300);
  EXPECT_DOUBLE_EQ(m.max, 3000);
  EXPECT_EQ(m.samples, 30);
}

TEST(CueflowReport, TriesEightRawConfigurations) {
  const auto configs = raw_configs();
  EXPECT_EQ(configs.size(), 8u);
  EXPECT_EQ(configs.front(), "waitset,sync,shm");
  EXPECT_EQ(configs.back(), "listener,async,udp");
}

TEST(CueflowReport, FastestIsTheLowestP50ThenTheLowestP90) {
  std::map<std::string, Latency> tried{{"waitset,sync,shm", {50, 70, 0, 0, 100}},
                                       {"listener,sync,shm", {40, 90, 0, 0, 100}},
                                       {"listener,async,shm", {40, 60, 0, 0, 100}},
                                       {"listener,sync,udp", {10, 10, 0, 0, 0}}};  // no samples
  EXPECT_EQ(fastest(tried), "listener,async,shm");
}

TEST(CueflowReport, FasterComparesP50ThenP90) {
  EXPECT_TRUE(faster({10, 90, 0, 0, 1}, {11, 20, 0, 0, 1}));
  EXPECT_TRUE(faster({10, 20, 0, 0, 1}, {10, 30, 0, 0, 1}));
  EXPECT_FALSE(faster({10, 30, 0, 0, 1}, {10, 30, 0, 0, 1}));
}

TEST(CueflowReport, FastestIsNoneWhenNothingDelivered) {
  EXPECT_EQ(fastest({}), std::nullopt);
  EXPECT_EQ(fastest({{"waitset,sync,shm", {}}}), std::nullopt);
}

TEST(CueflowReport, RawConfigBecomesTheProgramsOptions) {
  EXPECT_EQ(raw_config_args("waitset,async,udp"),
            (std::vector<std::string>{"--delivery", "waitset", "--publish", "async", "--transport",
                                      "udp"}));
  EXPECT_THROW(raw_config_args("waitset,async"), std::invalid_argument);
}

TEST(PeerCommon, QuantileClampsToTheLastValue) {
  const std::vector<std::int64_t> v{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  EXPECT_DOUBLE_EQ(quantile(v, 0.5), 6);
  EXPECT_DOUBLE_EQ(quantile(v, 0.99), 10);
  EXPECT_DOUBLE_EQ(quantile({}, 0.5), 0);
}

TEST(PeerCommon, PayloadsAreTheRowsSizes) {
  EXPECT_EQ(payload_bytes("Bool"), 1u);
  EXPECT_EQ(payload_bytes("LineSeg3DSeq"), 4800u);
  EXPECT_EQ(payload_bytes("GvImage"), 442368u);
}

}  // namespace
}  // namespace oscar::bench
