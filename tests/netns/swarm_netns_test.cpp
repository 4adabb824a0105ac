// The live swarm on two hosts (issue 18): config/swarm-warehouse-2hosts.yaml booted on two test
// hosts (network namespaces): ten robots on each, the coordinator, the job stream and the safety
// monitor on the first. Root only; skipped otherwise.
#include <fstream>
#include <regex>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "two_hosts.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;

std::string read(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

TEST(SwarmOnTwoHosts, RobotsOfBothHostsTakeJobsWithoutASafetyViolation) {
  if (const auto why = test::TestHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
  test::TestHosts hosts(2);
  const auto run = test::boot_on_two_hosts(hosts, "swarm-warehouse-2hosts.yaml", "warehouse2", 25);
  ASSERT_EQ(run.exit_code, 0) << run.boot_output;
  const auto& log_dir = run.log_dir;

  const auto coordinator = read(log_dir + "/pc1/coordinator.log");
  for (int i = 1; i <= 20; ++i) {
    EXPECT_NE(coordinator.find(fmt::format("robot 'r{}' joins planning", i)), std::string::npos)
        << "r" << i << " (on " << (i <= 10 ? "pc1" : "pc2") << ") never joined\n"
        << coordinator;
  }
  // The job stream's last count: at least 15 jobs committed in 25 s, none refused.
  std::smatch m;
  std::string last;
  const std::regex counts(R"((\d+) jobs sent, (\d+) committed, (\d+) refused or aborted)");
  for (auto it = std::sregex_iterator(coordinator.begin(), coordinator.end(), counts);
       it != std::sregex_iterator(); ++it) {
    m = *it;
    last = m.str();
  }
  ASSERT_FALSE(last.empty()) << coordinator;
  EXPECT_GE(std::stoi(m[2]), 15) << last;
  EXPECT_EQ(coordinator.find("violation"), std::string::npos);
  const auto monitor = read(log_dir + "/pc1/monitor.log");
  EXPECT_NE(monitor.find("started"), std::string::npos) << monitor;
  EXPECT_EQ(monitor.find("violation"), std::string::npos) << monitor;
  EXPECT_EQ(read(log_dir + "/pc2/fleet_b.log").find("error"), std::string::npos);
}

}  // namespace
}  // namespace oscar
