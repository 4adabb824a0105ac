// Seed 004 §4.2 on two hosts (issue 7): config/landmarks-2hosts.yaml booted on two test hosts
// (network namespaces); cam_b and MarkBDetect run on the second, the pose fusion prefetches
// MarkBDetect's result across the hosts. Root only; skipped otherwise.
#include <fstream>

#include <gtest/gtest.h>

#include "landmark_summary.hpp"
#include "two_hosts.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;

TEST(LandmarksOnTwoHosts, BootsAndFusesBothCamerasAsOnOneHost) {
  if (const auto why = test::TestHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
  test::TestHosts hosts(2);
  const auto run = test::boot_on_two_hosts(hosts, "landmarks-2hosts.yaml", "landmarks2", 8);
  ASSERT_EQ(run.exit_code, 0) << run.boot_output;
  const auto& log_dir = run.log_dir;

  const auto summaries = test::landmark_summaries(log_dir + "/pc1/landmarks.log");
  ASSERT_GE(summaries.size(), 4u) << run.boot_output;
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
