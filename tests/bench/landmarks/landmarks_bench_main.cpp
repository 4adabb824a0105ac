// oscar bench landmarks: processing time per cycle of seed 004 §4.2's landmark application —
// from the grab of the first image to the fused pose — with everything on one host
// (config/landmarks-1host.yaml, acquisition and detection one after the other) and on two test
// hosts (config/landmarks-2hosts.yaml, both cameras in parallel, prefetch from MarkBDetect).
// Prints a table, or JSON with --json. Reports what it measured; decides nothing by time.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/module_spec.hpp"
#include "oscar/network.hpp"
#include "oscar/perception_types.hpp"
#include "oscar/topic_io.hpp"
#include "percentile.hpp"  // tests/common
#include "process.hpp"     // tests/common
#include "source_tree.hpp"
#include "test_hosts.hpp"  // tests/netns

namespace {
using namespace std::chrono_literals;
namespace fs = std::filesystem;

std::string own_bin(const std::string& program) {
  return (fs::read_symlink("/proc/self/exe").parent_path() / program).string();
}
using oscar::test::percentile;

// --watch: subscribes to the fused pose (on the network of `host` in `system`) and writes one
// latency per pose that used both cameras: its last stamp minus the earlier of the two grabs.
int watch(const std::string& system, const std::string& host, int domain, double seconds,
          const std::string& out_file) {
  oscar::NetworkConfig network;
  if (!host.empty()) network = oscar::NetworkConfig::for_host(oscar::load_yaml_file(system), host);
  oscar::DdsParticipant p(domain, "bench:landmarks", network);
  auto q = oscar::qos::stream_reader(500);
  q.reliability().kind = eprosima::fastdds::dds::BEST_EFFORT_RELIABILITY_QOS;
  std::mutex mutex;
  std::vector<double> ms;
  std::atomic<bool> recording{false};
  oscar::TopicReader<oscar::LandmarkPose, oscar::LandmarkPosePubSubType> reader(
      p, "oscar/cue/pose/pose", q, [&](const oscar::LandmarkPose& c, const auto&) {
        const auto& st = c.header().stamps();
        if (!recording || st.size() != 5 || c.cameras().size() != 2) return;
        const auto first = std::min(st[0], st[2]);
        std::lock_guard lock(mutex);
        if (ms.size() < 5) {  // what the cycle consists of, for the log
          std::fprintf(stderr, "A grab %+.1f det %+.1f | B grab %+.1f det %+.1f | pose %+.1f ms\n",
                       (st[0] - first) / 1e6, (st[1] - first) / 1e6, (st[2] - first) / 1e6,
                       (st[3] - first) / 1e6, (st[4] - first) / 1e6);
        }
        ms.push_back(static_cast<double>(st[4] - first) / 1e6);
      });
  std::this_thread::sleep_for(2s);  // discovery and the first cycles
  recording = true;
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  recording = false;
  std::lock_guard lock(mutex);
  std::ofstream out(out_file);
  for (const auto v : ms) out << v << "\n";
  return 0;
}

struct Result {
  std::vector<double> ms;
};

// Boots `config` (rewritten: test domain, image size, hosts) with the watcher beside it.
Result run(const std::string& config, int width, int height, double seconds, bool two_hosts) {
  auto root = YAML::LoadFile(config);
  root.remove("domain");
  root["lease"] = "1s";
  for (auto m : root["modules"]) {
    for (auto k : m["kernels"]) {
      if (k["type"].as<std::string>() != "framegrabber") continue;
      k["params"]["width"] = width;
      k["params"]["height"] = height;
    }
  }
  std::unique_ptr<oscar::test::TestHosts> hosts;
  std::vector<std::string> prefix;
  std::string host;
  if (two_hosts) {
    hosts = std::make_unique<oscar::test::TestHosts>(2);
    root["hosts"]["pc1"]["address"] = hosts->address(1);
    root["hosts"]["pc2"]["netns"] = hosts->netns(2);
    root["hosts"]["pc2"]["address"] = hosts->address(2);
    prefix = hosts->on(1);
    host = "pc1";
  }
  const auto file =
      oscar::test::temp_path(two_hosts ? "bench_landmarks2" : "bench_landmarks1") + ".yaml";
  {
    YAML::Emitter e;
    e << root;
    std::ofstream(file) << e.c_str();
  }
  const int domain = 1 + static_cast<int>(getpid() % 200);
  auto boot_argv = prefix;
  boot_argv.insert(boot_argv.end(),
                   {own_bin("oscar-boot"), file, "--domain", std::to_string(domain), "--log-dir",
                    oscar::test::temp_path("bench_landmarks_logs"), "--timeout", "40", "--duration",
                    fmt::format("{:.0f}", seconds + 6)});
  oscar::test::Process boot(boot_argv, oscar::test::temp_path("bench_landmarks_boot.log"));
  std::this_thread::sleep_for(1s);
  const auto out = oscar::test::temp_path("bench_landmarks_ms") + ".txt";
  auto watch_argv = prefix;
  watch_argv.insert(watch_argv.end(), {own_bin("oscar-bench-landmarks"), "--watch", "--system",
                                       file, "--host", host, "--domain", std::to_string(domain),
                                       "--seconds", fmt::format("{}", seconds), "--out", out});
  oscar::test::Process watcher(
      watch_argv,
      oscar::test::temp_path(two_hosts ? "bench_landmarks_watch2" : "bench_landmarks_watch1"));
  if (watcher.wait(std::chrono::seconds(static_cast<int>(seconds) + 60)) != 0) {
    throw std::runtime_error("the watcher failed: " + watcher.output());
  }
  if (boot.wait(60s) != 0) throw std::runtime_error("boot failed: " + boot.output());
  Result r;
  std::ifstream in(out);
  for (double v; in >> v;) r.ms.push_back(v);
  if (r.ms.empty()) throw std::runtime_error("no fused poses from both cameras: " + boot.output());
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "oscar bench landmarks: per-cycle time from grabbing to the fused pose, one host "
      "vs two test hosts (seed 004 §4.2)"};
  bool json = false, watch_mode = false;
  double seconds = 10;
  int width = 640, height = 480, domain = 0;
  std::string system, host, out;
  app.add_flag("--json", json, "print JSON");
  app.add_option("--seconds", seconds, "measuring time per configuration");
  app.add_option("--width", width, "image width of both cameras (full frame)");
  app.add_option("--height", height, "image height of both cameras (full frame)");
  app.add_flag("--watch", watch_mode, "(internal) record pose latencies");
  app.add_option("--system", system);
  app.add_option("--host", host);
  app.add_option("--domain", domain);
  app.add_option("--out", out);
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    if (watch_mode) return watch(system, host, domain, seconds, out);
    if (const auto why = oscar::test::TestHosts::unavailable(); !why.empty()) {
      std::fprintf(stderr, "oscar bench landmarks: the two-host run %s\n", why.c_str());
      return 2;
    }
    const std::string dir = oscar::testing::source_path("config/");
    const auto one = run(dir + "landmarks-1host.yaml", width, height, seconds, false);
    const auto two = run(dir + "landmarks-2hosts.yaml", width, height, seconds, true);
    const double p50_1 = percentile(one.ms, 0.5), p50_2 = percentile(two.ms, 0.5);
    if (json) {
      std::printf("{\"one_host_ms_p50\": %.2f, \"two_hosts_ms_p50\": %.2f, \"speedup\": %.2f}\n",
                  p50_1, p50_2, p50_1 / p50_2);
      return 0;
    }
    std::printf(
        "landmarks, %dx%d images, %.0f s each (cycles: grab of the first image -> fused pose)\n",
        width, height, seconds);
    std::printf("%-10s %7s %9s %9s %9s\n", "config", "cycles", "p50 ms", "p99 ms", "max ms");
    std::printf("%-10s %7zu %9.2f %9.2f %9.2f\n", "one host", one.ms.size(), p50_1,
                percentile(one.ms, 0.99), percentile(one.ms, 1.0));
    std::printf("%-10s %7zu %9.2f %9.2f %9.2f\n", "two hosts", two.ms.size(), p50_2,
                percentile(two.ms, 0.99), percentile(two.ms, 1.0));
    std::printf("speedup (p50 one host / p50 two hosts): %.2f\n", p50_1 / p50_2);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench landmarks: %s\n", e.what());
    return 1;
  }
}
