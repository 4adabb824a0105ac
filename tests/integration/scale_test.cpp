// Discovery that scales (docs/network.md): a hundred modules on one host, with static peers and
// with a discovery server.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "oscar/testing/booted_system.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using ::testing::HasSubstr;

// `pairs` sources, each read by a sink of its own: 2 * pairs modules, one process each.
std::string source_sink_pairs(const std::string& name, int pairs, const std::string& network) {
  std::string yaml = "system: " + name + "\nlease: 2s\n" + network + "modules:\n";
  for (int i = 0; i < pairs; ++i) {
    const auto n = std::to_string(i);
    yaml += "  - name: src" + n + "\n    kernels: [ { type: bench_source, name: src" + n +
            ", params: { type: Bool } } ]\n    mode: { continuous: 100ms }\n";
    yaml += "  - name: sink" + n + "\n    kernels: [ { type: bench_sink, name: sink" + n +
            ", params: { type: Bool }, inputs: { in: src" + n +
            "/out } } ]\n    mode: single_step\n";
  }
  return yaml;
}

std::string write_system(const std::string& name, const std::string& yaml) {
  const auto file = test::temp_path(name) + ".yaml";
  std::ofstream(file) << yaml;
  return file;
}

// Every sink has run on cues of its source.
bool every_sink_ran(const SystemState& s, int pairs, unsigned long long cycles) {
  for (int i = 0; i < pairs; ++i) {
    const auto* m = test::entry(s, "sink" + std::to_string(i));
    if (!m || m->state().kernels().empty() || m->state().kernels()[0].cycles() < cycles) {
      return false;
    }
  }
  return true;
}

// Boots 2 * pairs modules, checks that each runs, that cues reach every sink and that oscar ps
// lists them all; prints the time from boot to running.
void boot_and_check(const std::string& name, int pairs, const std::string& network) {
  const auto file = write_system(name, source_sink_pairs(name, pairs, network));
  const auto started = std::chrono::steady_clock::now();
  // test_domain(): 1-200, where each address has room for 120 participant ids (232 has 63).
  testing::SystemUnderTest sys(
      file, {.domain = test::test_domain(), .boot_timeout = 100s, .log_dir = ""});
  ASSERT_TRUE(sys.wait_until_running({}, 100s)) << sys.boot_output();
  const auto boot_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                           std::chrono::steady_clock::now() - started)
                           .count();
  std::printf("%s: %d modules running %lld ms after boot started\n", name.c_str(), 2 * pairs,
              static_cast<long long>(boot_ms));
  const auto s =
      sys.wait_for([&](const SystemState& st) { return every_sink_ran(st, pairs, 3); }, 60s);
  ASSERT_TRUE(s) << "cues did not reach every sink";
  ASSERT_EQ(s->modules().size(), static_cast<std::size_t>(2 * pairs));

  test::Process ps({test::bin("oscar-ps"), "--system", file, "--domain",
                    std::to_string(sys.domain()), "--json", "--timeout", "20"},
                   test::temp_path(name + "_ps") + ".log");
  ASSERT_EQ(ps.wait(60s), 0) << ps.output();
  const auto j = nlohmann::json::parse(ps.output());
  ASSERT_EQ(j["modules"].size(), static_cast<std::size_t>(2 * pairs));
  for (const auto& m : j["modules"]) EXPECT_EQ(m["status"], "running") << m["name"];

  EXPECT_EQ(sys.shut_down(60s), 0) << sys.boot_output();
  EXPECT_TRUE(sys.leftover_processes().empty());
  std::filesystem::remove(file);
}

TEST(Scale, SixtyFourModulesOnOneHostBootRunAndAreListedWithStaticPeers) {
  boot_and_check("many_static", 32, "");
}

TEST(Scale, SixtyFourModulesOnOneHostBootRunAndAreListedWithADiscoveryServer) {
  boot_and_check("many_server", 32, "network: { discovery: server }\n");
}

}  // namespace
}  // namespace oscar
