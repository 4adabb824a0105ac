#include "bench_sink_kernel.hpp"

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

}  // namespace
}  // namespace oscar::modules
