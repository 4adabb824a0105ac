#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <oscar/harness.hpp>
#include <oscar/perception_types.hpp>
#include <oscar/testing/conformance.hpp>

namespace oscar {
namespace {
using ::testing::ElementsAre;
using ::testing::HasSubstr;

Eigen::Vector3d trans(const Pose3& p) { return {p.t()[0], p.t()[1], p.t()[2]}; }
Eigen::Quaterniond quat(const Pose3& p) { return {p.q()[0], p.q()[1], p.q()[2], p.q()[3]}; }

TagDetections tags(const std::string& camera, double camera_x, int id, Eigen::Vector3d t,
                   Stamp acquired) {
  TagDetections d;
  d.camera_id(camera);
  d.position({camera_x, 0, 0});
  append_stamp(d.header(), acquired);
  append_stamp(d.header(), acquired + 1000);
  TagDetection det;
  det.id(id);
  det.has_pose(true);
  det.pose().t({t.x(), t.y(), t.z()});
  det.pose().q({1, 0, 0, 0});
  d.detections().push_back(det);
  return d;
}

TEST(LandmarkPose, FusesBothCamerasIntoTheTargetPoseAndKeepsAllStamps) {
  KernelHarness h("landmark_pose", YAML::Load("{}"));
  // Target at (0, 0, 1): tag 0 sits 8 cm left of it, tag 1 8 cm right; camera B is 10 cm right.
  h.feed("tags_b", tags("cam_b", 0.1, 1, {-0.02, 0, 1}, 5'000));
  h.feed("tags_a", tags("cam_a", 0.0, 0, {-0.08, 0, 1}, 4'000));
  h.step();
  const auto out = h.take<oscar::LandmarkPose>("pose").at(0);
  EXPECT_TRUE(out->valid());
  EXPECT_EQ(out->estimates(), 2u);
  EXPECT_LT((trans(out->pose()) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
  EXPECT_LT(out->spread_m(), 1e-12);
  EXPECT_THAT(out->tag_ids(), ElementsAre(0, 1));
  EXPECT_THAT(out->cameras(), ElementsAre("cam_a", "cam_b"));
  EXPECT_THAT(out->header().stamps(), ElementsAre(4'000u, 5'000u, 5'000u, 6'000u,
                                                  static_cast<unsigned long long>(h.now())));
}

TEST(LandmarkPose, WithoutAMatchingImageOfBItUsesAAlone) {
  KernelHarness h("landmark_pose", YAML::Load("{max_skew: 10ms}"));
  h.feed("tags_b", tags("cam_b", 0.1, 1, {0.5, 0, 1}, 1'000'000'000));
  h.feed("tags_a", tags("cam_a", 0.0, 0, {-0.08, 0, 2}, 1'100'000'000));  // 100 ms later
  h.step();
  const auto out = h.take<oscar::LandmarkPose>("pose").at(0);
  EXPECT_EQ(out->estimates(), 1u);
  EXPECT_LT((trans(out->pose()) - Eigen::Vector3d(0, 0, 2)).norm(), 1e-12);
  EXPECT_EQ(out->header().stamps().size(), 3u);
}

TEST(LandmarkPose, PrefetchesBFromItsProducer) {
  KernelHarness h("landmark_pose", YAML::Load("{wait_b: 20ms}"), "pose",
                  {{"tags_b", InputOverrides{.depth = {}, .transfer = Transfer::kPrefetch}}});
  h.feed("tags_b", tags("cam_b", 0.1, 1, {-0.02, 0.01, 1}, 7'000));
  h.feed("tags_a", tags("cam_a", 0.0, 0, {-0.08, -0.01, 1}, 7'000));
  h.step();
  const auto out = h.take<oscar::LandmarkPose>("pose").at(0);
  EXPECT_EQ(out->estimates(), 2u);
  EXPECT_NEAR(out->spread_m(), 0.01, 1e-12);
}

TEST(LandmarkPose, WithPrefetchAnOlderResultOfBIsNotTakenAndTheWaitEndsWithAAlone) {
  KernelHarness h("landmark_pose", YAML::Load("{wait_b: 20ms, max_skew: 10ms}"), "pose",
                  {{"tags_b", InputOverrides{.depth = {}, .transfer = Transfer::kPrefetch}}});
  h.feed("tags_b", tags("cam_b", 0.1, 1, {0.5, 0, 1}, 1'000'000'000));
  h.feed("tags_a", tags("cam_a", 0.0, 0, {-0.08, 0, 2}, 1'100'000'000));  // 100 ms later
  h.step();  // asks B for its first result at most 10 ms older than A's image: none in 20 ms
  const auto out = h.take<oscar::LandmarkPose>("pose").at(0);
  EXPECT_EQ(out->estimates(), 1u);
  EXPECT_THAT(out->cameras(), ElementsAre("cam_a"));
}

TEST(LandmarkPose, AWaitForBLongerThanAProducerHoldsAPullIsRefused) {
  try {
    KernelHarness h("landmark_pose", YAML::Load("{wait_b: 11s}"));
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("wait_b"));
  }
}

TEST(LandmarkPose, TagsOutsideTheLayoutOrWithoutPoseAreNoEstimates) {
  KernelHarness h("landmark_pose", YAML::Load("{tag_layout: '4:0,0,0'}"));
  h.feed("tags_a", tags("cam_a", 0, 0, {0, 0, 1}, 1));
  h.step();
  const auto out = h.take<oscar::LandmarkPose>("pose").at(0);
  EXPECT_FALSE(out->valid());
  EXPECT_EQ(out->estimates(), 0u);
  h.step();  // nothing new from A: nothing published
  EXPECT_EQ(h.take_count("pose"), 0u);
}

TEST(LandmarkPose, ABadLayoutIsRefused) {
  try {
    KernelHarness h("landmark_pose", YAML::Load("{tag_layout: '0=1,2,3'}"));
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("tag layout entry '0=1,2,3': expected 'id:x,y,z'"));
  }
}

TEST(LandmarkPose, FusedPoseOfTheSyntheticSceneMatchesTheGroundTruth) {
  KernelHarness cam_a("framegrabber", YAML::Load("{}"), "cam_a");
  KernelHarness cam_b("framegrabber", YAML::Load("{position_m: '0.1,0,0'}"), "cam_b");
  KernelHarness mark_a("apriltag_detect", YAML::Load("{ids: '0'}"), "mark_a");
  KernelHarness mark_b("apriltag_detect", YAML::Load("{ids: '1'}"), "mark_b");
  KernelHarness fuse("landmark_pose", YAML::Load("{}"), "pose");
  double worst_m = 0, worst_deg = 0;
  for (int i = 0; i < 10; ++i) {
    for (auto* h : {&cam_a, &cam_b}) h->advance(std::chrono::milliseconds(100));  // 10 Hz
    cam_a.step();
    cam_b.step();
    mark_a.feed("image", *cam_a.take<CameraImage>("frame").at(0));
    mark_b.feed("image", *cam_b.take<CameraImage>("frame").at(0));
    mark_a.step();
    mark_b.step();
    fuse.feed("tags_b", *mark_b.take<TagDetections>("tags").at(0));
    fuse.feed("tags_a", *mark_a.take<TagDetections>("tags").at(0));
    fuse.step();
    const auto out = fuse.take<oscar::LandmarkPose>("pose").at(0);
    ASSERT_EQ(out->estimates(), 2u) << "frame " << i;
    ASSERT_TRUE(out->truth().valid());
    worst_m = std::max(worst_m, (trans(out->pose()) - trans(out->truth().target())).norm());
    worst_deg = std::max(
        worst_deg, quat(out->pose()).angularDistance(quat(out->truth().target())) * 180 / M_PI);
  }
  EXPECT_LT(worst_m, 0.01);  // stated tolerance: 1 cm and 2 degrees
  EXPECT_LT(worst_deg, 2.0);
  RecordProperty("worst_position_m", std::to_string(worst_m));
  RecordProperty("worst_angle_deg", std::to_string(worst_deg));
}

TEST(LandmarkPose, StubPublishesAPlausiblePose) {
  KernelHarness h("landmark_pose", YAML::Load("{}"));
  h.step_stub();
  const auto out = h.take<oscar::LandmarkPose>("pose").at(0);
  EXPECT_TRUE(out->valid());
  EXPECT_DOUBLE_EQ(out->pose().t()[2], 0.7);
  EXPECT_THAT(out->tag_ids(), ElementsAre(0, 1));
}

}  // namespace
}  // namespace oscar

OSCAR_KERNEL_CONFORMANCE_TEST(LandmarkPose, "landmark_pose", "{}")
