// Seed 004 §4.2 on two hosts (issue 7): config/landmarks-2hosts.yaml booted on two test hosts
// (network namespaces); cam_b and MarkBDetect run on the second, the pose fusion prefetches
// MarkBDetect's result across the hosts. Root only; skipped otherwise.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "landmark_summary.hpp"
#include "process.hpp"
#include "test_hosts.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;

TEST(LandmarksOnTwoHosts, BootsAndFusesBothCamerasAsOnOneHost) {
  if (const auto why = test::TestHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
  test::TestHosts hosts(2);
  auto root = YAML::LoadFile(std::string(OSCAR_SOURCE_DIR) + "/config/landmarks-2hosts.yaml");
  root.remove("domain");
  root["lease"] = "1s";  // as the other booted-system tests on a loaded machine
  root["hosts"]["pc1"]["address"] = hosts.address(1);
  root["hosts"]["pc2"]["netns"] = hosts.netns(2);
  root["hosts"]["pc2"]["address"] = hosts.address(2);
  const auto file = test::temp_path("landmarks2") + ".yaml";
  {
    YAML::Emitter out;
    out << root;
    std::ofstream(file) << out.c_str();
  }
  const auto log_dir = test::temp_path("landmarks2_logs");
  std::filesystem::remove_all(log_dir);
  auto argv = hosts.on(1);  // boot and the registry run on pc1
  argv.insert(argv.end(),
              {test::bin("oscar-boot"), file, "--domain", std::to_string(test::test_domain()),
               "--log-dir", log_dir, "--timeout", "40", "--duration", "8"});
  test::Process boot(argv, test::temp_path("landmarks2_boot.log"));
  ASSERT_EQ(boot.wait(90s), 0) << boot.output();

  const auto summaries = test::landmark_summaries(log_dir + "/pc1/landmarks.log");
  ASSERT_GE(summaries.size(), 4u) << boot.output();
  // The first seconds include discovery across the hosts; from the third summary on, every
  // cycle's pose uses both cameras, at CobraControl's 10 Hz, near the ground truth.
  for (std::size_t i = 2; i < summaries.size(); ++i) {
    const auto& s = summaries[i];
    EXPECT_GE(s.rate_hz, 8.0) << "summary " << i;
    EXPECT_LE(s.rate_hz, 12.0) << "summary " << i;
    EXPECT_GE(s.both, s.poses - 1) << "summary " << i << ": B missing from poses";
    EXPECT_TRUE(s.truth);
    EXPECT_LT(s.worst_mm, 10.0) << "summary " << i;
    EXPECT_LT(s.worst_deg, 2.0) << "summary " << i;
  }
  std::ifstream b(log_dir + "/pc2/cameras_b.log");
  const std::string text((std::istreambuf_iterator<char>(b)), {});
  EXPECT_NE(text.find("started"), std::string::npos);
  EXPECT_EQ(text.find("error"), std::string::npos) << text;
}

}  // namespace
}  // namespace oscar
