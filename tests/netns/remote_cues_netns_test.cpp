// Cues between two test hosts over UDP (issue 21 item 2, the remote constellation of `oscar bench
// cueflow`): a producer on host 1 sends a few hundred 768x576 images, 100-line LineSeg3DSeqs and
// Bools to a consumer on host 2, with shared memory off, so every byte crosses the veth between the
// namespaces. The consumer checks that the sequence numbers have no gap or duplicate and that
// each payload's checksum is the producer's. Root only; skipped otherwise.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "process.hpp"  // tests/common
#include "test_hosts.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using nlohmann::json;

constexpr int kCues = 300;  // per type
constexpr std::size_t kImageBytes = 768u * 576u;
constexpr int kLostAtStart = 50;  // at most, before discovery matched writer and reader (1 s)

// The bytes received on a test host's interfaces other than loopback.
std::uint64_t received_bytes(const test::TestHosts& hosts, int i) {
  const auto out = test::temp_path("remote_cues_link") + ".json";
  const auto cmd = fmt::format("ip -n {} -j -s link show > {}", hosts.netns(i), out);
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("failed: " + cmd);
  std::uint64_t bytes = 0;
  for (const auto& link : json::parse(std::ifstream(out))) {
    if (link["ifname"] != "lo") bytes += link["stats64"]["rx"]["bytes"].get<std::uint64_t>();
  }
  return bytes;
}

std::string network(const test::TestHosts& hosts, int i) {
  return fmt::format("{{interfaces: [{}], peers: [{}, {}], shared_memory: false}}",
                     hosts.address(i), hosts.address(1), hosts.address(2));
}

TEST(RemoteCues, ArriveCompleteAndUncorruptedOverUdpBetweenTwoHosts) {
  if (const auto why = test::TestHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
  test::TestHosts hosts(2);
  // Domains 141-149 are this test family's; the hosts' own network hears no one else anyway.
  const auto domain = std::to_string(141 + getpid() % 9);
  // One source and one checking sink per type, side by side in one module on each host.
  const std::pair<std::string, std::string> kinds[] = {
      {"image", "GvImage"}, {"lines", "LineSeg3DSeq"}, {"flag", "Bool"}};
  std::string sinks, sources;
  std::map<std::string, std::string> reports;  // by type
  for (const auto& [name, type] : kinds) {
    reports[type] = test::temp_path("remote_cues_" + name) + ".json";
    std::filesystem::remove(reports[type]);
    sinks += fmt::format(
        "  - {{ type: bench_sink, name: {}_sink, inputs: {{ in: {}/out }},\n"
        "      params: {{ type: {}, verify: true, expect: {}, report: '{}' }} }}\n",
        name, name, type, kCues, reports[type]);
    sources +=
        fmt::format("  - {{ type: bench_source, name: {}, params: {{ type: {}, count: {} }} }}\n",
                    name, type, kCues);
  }
  const auto sink_file = test::temp_path("remote_cues_sink") + ".yaml";
  const auto source_file = test::temp_path("remote_cues_src") + ".yaml";
  std::ofstream(sink_file) << fmt::format(
      "name: sink\nnetwork: {}\nmode: single_step\nkernels:\n{}", network(hosts, 2), sinks);
  std::ofstream(source_file) << fmt::format(
      "name: src\nnetwork: {}\nmode: {{ continuous: 20ms }}\nkernels:\n{}", network(hosts, 1),
      sources);

  const auto before = received_bytes(hosts, 2);
  auto argv = hosts.on(2);
  argv.insert(argv.end(), {test::bin("oscar-run"), sink_file, "--domain", domain});
  test::Process sink(argv, test::temp_path("remote_cues_sink") + ".log");
  std::this_thread::sleep_for(1s);  // the reader exists before the first cue
  argv = hosts.on(1);
  argv.insert(argv.end(), {test::bin("oscar-run"), source_file, "--domain", domain});
  test::Process source(argv, test::temp_path("remote_cues_src") + ".log");
  // 300 cues at 20 ms: 6 s. A sink that missed the first cues (sent before the writer matched
  // it) never counts 300: it reports what it has when stopped, twice that time later.
  const auto until = std::chrono::steady_clock::now() + 2 * kCues * 20ms + 3s;
  const auto all_reported = [&] {
    return std::all_of(reports.begin(), reports.end(),
                       [](const auto& r) { return std::filesystem::exists(r.second); });
  };
  while (!all_reported() && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(100ms);
  }
  std::this_thread::sleep_for(500ms);  // a duplicate after the last cue would be counted
  sink.stop();                         // writes the reports that are not yet written
  source.stop();
  const auto crossed = received_bytes(hosts, 2) - before;

  for (const auto& [type, file] : reports) {
    SCOPED_TRACE(type);
    std::ifstream in(file);
    ASSERT_TRUE(in) << "no report; sink:\n" << sink.output() << "\nsource:\n" << source.output();
    const auto r = json::parse(in);
    // Cues written before the writer matched the reader are not delivered (volatile); every one
    // after the first that arrived must arrive, once, as sent.
    EXPECT_EQ(r["last_seq"], kCues) << r.dump();
    EXPECT_LE(r["first_seq"].get<int>(), kLostAtStart) << r.dump();
    EXPECT_EQ(r["received"].get<int>(), kCues - r["first_seq"].get<int>() + 1) << r.dump();
    EXPECT_EQ(r["gaps"], 0) << r.dump();
    EXPECT_EQ(r["duplicates"], 0) << r.dump();
    EXPECT_EQ(r["verified"], r["received"]) << r.dump();
    EXPECT_EQ(r["corrupt"], 0) << r.dump();
  }
  // Over UDP through the veth, not through shared memory: all image bytes came into host 2.
  EXPECT_GE(crossed, (kCues - kLostAtStart) * kImageBytes);
}

}  // namespace
}  // namespace oscar
