#include "bench_sink_kernel.hpp"

#include "bench_pattern.hpp"  // modules/bench_source

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <oscar/harness.hpp>
#include <oscar/testing/conformance.hpp>

namespace oscar::modules {
namespace {

OSCAR_KERNEL_CONFORMANCE_TEST(BenchSink, "bench_sink", "{type: Bool}")

Bool numbered(unsigned long long seq, Stamp stamp) {
  Bool b;
  b.header().seq(seq);
  append_stamp(b.header(), stamp);
  return b;
}

TEST(BenchSink, CountsGapsAndDuplicatesBySequenceNumber) {
  KernelHarness h("bench_sink", YAML::Load("{type: Bool}"));
  for (unsigned long long seq : {1, 2, 5, 5, 6, 9}) h.feed("in", numbered(seq, 100));
  h.step();
  auto& sink = dynamic_cast<BenchSink&>(h.kernel());
  EXPECT_EQ(sink.stats().received, 5u);
  EXPECT_EQ(sink.stats().gaps, 2u + 2u);
  EXPECT_EQ(sink.stats().duplicates, 1u);
  EXPECT_EQ(sink.stats().last_seq, 9u);
}

TEST(BenchSink, MeasuresLatencyFromTheFirstStampAndWritesAReport) {
  const auto file = std::filesystem::temp_directory_path() / "oscar_bench_sink_test.json";
  std::filesystem::remove(file);
  KernelHarness h("bench_sink",
                  YAML::Load("{type: Bool, expect: 2, report: '" + file.string() + "'}"));
  const Stamp now = wall_now();
  h.feed("in", numbered(1, now - 2'000'000));  // generated 2 ms ago
  h.feed("in", numbered(2, now - 1'000'000));
  h.set_now(now + 1'000'000);
  h.step();
  std::ifstream in(file);
  ASSERT_TRUE(in) << "no report at " << file;
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["received"], 2);
  EXPECT_EQ(report["samples"], 2);
  EXPECT_GE(report["delivery_us"]["p50"].get<double>(), 1000.0);
  EXPECT_GE(report["process_us"]["max"].get<double>(), 3000.0);
  EXPECT_LT(report["process_us"]["max"].get<double>(), 3100.0);
}

TEST(BenchSink, VerifyCountsImagesWhosePayloadIsNotTheSources) {
  KernelHarness h("bench_sink", YAML::Load("{type: GvImage, verify: true}"));
  auto image = bench_pattern::image(64, 48);
  image.header().seq(1);
  h.feed("in", image);
  image.header().seq(2);
  image.image()[1000] ^= 0x01;  // one bit flipped
  h.feed("in", image);
  image.header().seq(3);
  image.image()[1000] ^= 0x01;
  image.image().pop_back();  // one byte short
  h.feed("in", image);
  h.step();
  auto& sink = dynamic_cast<BenchSink&>(h.kernel());
  EXPECT_EQ(sink.stats().verified, 3u);
  EXPECT_EQ(sink.stats().corrupt, 2u);
  EXPECT_EQ(sink.stats().first_seq, 1u);
  EXPECT_THAT(sink.report(), testing::HasSubstr(R"("verified":3,"corrupt":2)"));
}

TEST(BenchSink, VerifyAcceptsTheSourcesLinesAndBool) {
  KernelHarness lines("bench_sink", YAML::Load("{type: LineSeg3DSeq, verify: true}"));
  auto seq = bench_pattern::lines(100);
  seq.header().seq(1);
  lines.feed("in", seq);
  seq.header().seq(2);
  seq.lines()[99].ez(1.5);
  lines.feed("in", seq);
  lines.step();
  EXPECT_EQ(dynamic_cast<BenchSink&>(lines.kernel()).stats().corrupt, 1u);
  KernelHarness flag("bench_sink", YAML::Load("{type: Bool, verify: true}"));
  auto b = numbered(1, 100);
  b.value(true);
  flag.feed("in", b);
  flag.step();
  EXPECT_EQ(dynamic_cast<BenchSink&>(flag.kernel()).stats().verified, 1u);
  EXPECT_EQ(dynamic_cast<BenchSink&>(flag.kernel()).stats().corrupt, 0u);
}

}  // namespace
}  // namespace oscar::modules
