// The arithmetic of `oscar bench cueflow` (cueflow_report.hpp and peer_common.hpp) and the
// Cyclone peer's reach (cyclone_reach.hpp), no timing.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>

#include "cueflow_report.hpp"
#include "peers/cyclone_reach.hpp"
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
  EXPECT_DOUBLE_EQ(l.process_p50, 0) << "only bench_sink's report has it";
}

// bench_sink also says when process() read each cue: the hand-over to the processing thread.
TEST(CueflowReport, ReadsBenchSinksProcessLatencyAndMediansIt) {
  const auto sink = [](double p50) {
    return parse_report(nlohmann::json::parse(
        fmt::format(R"({{"samples":5,"delivery_us":{{"p50":1,"p90":2,"max":3}},)"
                    R"("process_us":{{"p50":{},"p90":{},"max":40}}}})",
                    p50, 2 * p50)));
  };
  const auto l = sink(7.5);
  EXPECT_DOUBLE_EQ(l.process_p50, 7.5);
  EXPECT_DOUBLE_EQ(l.process_p90, 15);
  const auto m = median_of({sink(9), sink(3), sink(6)});
  EXPECT_DOUBLE_EQ(m.process_p50, 6);
  EXPECT_DOUBLE_EQ(m.process_p90, 12);
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

TEST(CueflowReport, TheAchievedRateIsTheMeasuredCuesOverTheirSpan) {
  const auto l = parse_report(nlohmann::json::parse(
      R"({"samples":1001,"span_s":2.0,"delivery_us":{"p50":1,"p90":2,"max":3}})"));
  EXPECT_DOUBLE_EQ(l.rate_hz(), 500);
  EXPECT_DOUBLE_EQ(Latency{}.rate_hz(), 0) << "no span: no rate";
}

TEST(CueflowReport, ReadsGapsAndTakesNoneAsZero) {
  EXPECT_EQ(parse_report(nlohmann::json::parse(
                             R"({"samples":5,"gaps":3,"delivery_us":{"p50":1,"p90":2,"max":3}})"))
                .gaps,
            3);
  EXPECT_EQ(parse_report(
                nlohmann::json::parse(R"({"samples":5,"delivery_us":{"p50":1,"p90":2,"max":3}})"))
                .gaps,
            0);
}

// A link that loses cues above 3000 Hz: doubling from 500 passes 500..2000 and fails 4000;
// three bisections try 3000 (passes), 3500 and 3250 (fail).
TEST(Throughput, DoublesUntilALossThenBisects) {
  const auto t = highest_lossless_rate(500, 100000, 3, [](double rate) -> std::optional<Trial> {
    if (rate > 3000) return std::nullopt;
    return Trial{rate / 100, rate * 0.9};  // the CPU % of that trial, the rate it achieved
  });
  EXPECT_DOUBLE_EQ(t.rate_hz, 3000);
  EXPECT_DOUBLE_EQ(t.at.cpu_pct, 30);
  EXPECT_DOUBLE_EQ(t.at.achieved_hz, 2700);
  EXPECT_EQ(t.tried, (std::vector<double>{500, 1000, 2000, 4000, 3000, 3500, 3250}));
}

TEST(Throughput, StopsAtTheCapAndSaysNothingPassedWhenTheFirstTrialLoses) {
  const auto all =
      highest_lossless_rate(500, 2000, 3, [](double) -> std::optional<Trial> { return Trial{}; });
  EXPECT_DOUBLE_EQ(all.rate_hz, 2000);
  EXPECT_EQ(all.tried.size(), 3u);
  const auto none =
      highest_lossless_rate(500, 2000, 3, [](double) -> std::optional<Trial> { return {}; });
  EXPECT_DOUBLE_EQ(none.rate_hz, 0);
  EXPECT_EQ(none.tried, std::vector<double>{500});
}

TEST(PeerCommon, CountsTheCuesMissingBetweenTwoThatArrived) {
  PeerOptions o;
  o.expect = 10;
  o.warmup = 0;
  o.report = ::testing::TempDir() + "/peer_gaps.json";
  LatencyLog log(o);
  for (const std::uint64_t seq : {3, 4, 7, 8, 12}) log.add(1000, seq);
  log.write_report();
  const auto j = nlohmann::json::parse(std::ifstream(o.report));
  EXPECT_EQ(j["gaps"], 5);  // 5, 6, 9, 10, 11; nothing before the first that arrived
  EXPECT_EQ(j["received"], 5);
  EXPECT_GE(j["span_s"].get<double>(), 0.0);
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

TEST(CycloneReach, LoopbackOnlyByDefault) {
  const auto xml = cyclone_config({});
  EXPECT_NE(xml.find("<NetworkInterface name=\"lo\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<Peer address=\"localhost\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos) << xml;
  EXPECT_EQ(xml.find("SocketReceiveBufferSize"), std::string::npos) << xml;
}

TEST(CycloneReach, ATestHostsAddressWithItsPeersAndBuffers) {
  const Reach reach{"10.77.5.2", {"10.77.5.1", "10.77.5.2"}, 4u << 20};
  EXPECT_EQ(reach_error(reach), "");
  const auto xml = cyclone_config(reach);
  EXPECT_NE(xml.find("<NetworkInterface address=\"10.77.5.2\"/>"), std::string::npos) << xml;
  EXPECT_EQ(xml.find("name=\"lo\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<Peer address=\"10.77.5.1\"/><Peer address=\"10.77.5.2\"/>"),
            std::string::npos)
      << xml;
  EXPECT_EQ(xml.find("localhost"), std::string::npos) << xml;
  EXPECT_NE(xml.find("max=\"4194304B\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos) << xml;
}

TEST(CycloneReach, BadOptionsAreNamedWithTheRule) {
  EXPECT_EQ(reach_error({"10.77.5.x", {"10.77.5.1"}, 0}),
            "--address '10.77.5.x': not an IPv4 address");
  EXPECT_EQ(reach_error({"10.77.5.2", {}, 0}),
            "--address needs --peer (where discovery looks, one per host)");
  EXPECT_EQ(reach_error({"10.77.5.2", {"robot"}, 0}), "--peer 'robot': not an IPv4 address");
  EXPECT_EQ(reach_error({"", {"10.77.5.1"}, 0}),
            "--peer goes with --address (without it: loopback only)");
}

}  // namespace
}  // namespace oscar::bench
