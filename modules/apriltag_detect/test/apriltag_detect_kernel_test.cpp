#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <oscar/harness.hpp>
#include <oscar/perception_types.hpp>
#include <oscar/testing/conformance.hpp>

namespace oscar {
namespace {
using ::testing::HasSubstr;

Eigen::Quaterniond quat(const Pose3& p) { return {p.q()[0], p.q()[1], p.q()[2], p.q()[3]}; }
Eigen::Vector3d trans(const Pose3& p) { return {p.t()[0], p.t()[1], p.t()[2]}; }

std::string error_of(KernelHarness& h) {
  try {
    h.step();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

// Tolerances stated for the synthetic scene (640x480, fx = 640, 0.1 m tags 0.5..0.9 m away):
constexpr double kCornerPx = 1.0;
constexpr double kPositionM = 0.01;
constexpr double kAngleDeg = 3.0;

struct Run {
  int frames = 0, tags = 0;
  double worst_corner_px = 0, worst_position_m = 0, worst_angle_deg = 0;
};

Run detect_synthetic(const std::string& grabber_params, const std::string& detector_params,
                     int frames) {
  KernelHarness grab("framegrabber", YAML::Load(grabber_params), "cam");
  KernelHarness det("apriltag_detect", YAML::Load(detector_params), "mark");
  Run run;
  for (int i = 0; i < frames; ++i) {
    grab.step();
    const auto frame = grab.take<CameraImage>("frame").at(0);
    det.feed("image", *frame);
    det.step();
    const auto out = det.take<TagDetections>("tags").at(0);
    ++run.frames;
    EXPECT_EQ(out->detections().size(), frame->truth().tags().size()) << "frame " << i;
    for (const auto& truth : frame->truth().tags()) {
      const auto it = std::find_if(out->detections().begin(), out->detections().end(),
                                   [&](const TagDetection& d) { return d.id() == truth.id(); });
      if (it == out->detections().end()) {
        ADD_FAILURE() << "tag " << truth.id() << " not detected in frame " << i;
        continue;
      }
      ++run.tags;
      for (int k = 0; k < 8; ++k) {
        run.worst_corner_px =
            std::max(run.worst_corner_px, std::abs(it->corners()[k] - truth.corners()[k]));
      }
      if (it->has_pose()) {
        run.worst_position_m =
            std::max(run.worst_position_m, (trans(it->pose()) - trans(truth.pose())).norm());
        run.worst_angle_deg = std::max(
            run.worst_angle_deg, quat(it->pose()).angularDistance(quat(truth.pose())) * 180 / M_PI);
      }
    }
  }
  return run;
}

TEST(AprilTagDetect, FindsTheSyntheticTagsWithCornersWithinOnePixelAndPosesNearTheTruth) {
  const auto run = detect_synthetic("{source: synthetic:moving}", "{}", 20);
  EXPECT_EQ(run.tags, 40);
  EXPECT_LT(run.worst_corner_px, kCornerPx);
  EXPECT_LT(run.worst_position_m, kPositionM);
  EXPECT_LT(run.worst_angle_deg, kAngleDeg);
  RecordProperty("worst_corner_px", std::to_string(run.worst_corner_px));
  RecordProperty("worst_position_m", std::to_string(run.worst_position_m));
  RecordProperty("worst_angle_deg", std::to_string(run.worst_angle_deg));
}

TEST(AprilTagDetect, CopesWithNoiseAndBlur) {
  const auto run = detect_synthetic(
      "{source: synthetic:moving, noise_sigma: 4, blur_sigma_px: 0.8, seed: 7}", "{}", 10);
  EXPECT_EQ(run.tags, 20);
  EXPECT_LT(run.worst_corner_px, kCornerPx);
  EXPECT_LT(run.worst_position_m, 2 * kPositionM);
}

TEST(AprilTagDetect, KeepsOnlyTheIdsItIsGiven) {
  KernelHarness grab("framegrabber", YAML::Load("{}"));
  KernelHarness det("apriltag_detect", YAML::Load("{ids: '1'}"));
  grab.step();
  det.feed("image", *grab.take<CameraImage>("frame").at(0));
  det.step();
  const auto out = det.take<TagDetections>("tags").at(0);
  ASSERT_EQ(out->detections().size(), 1u);
  EXPECT_EQ(out->detections()[0].id(), 1);
  EXPECT_EQ(out->detections()[0].family(), "tag36h11");
}

TEST(AprilTagDetect, CopiesTheImageStampsAndAppendsItsOwn) {
  KernelHarness det("apriltag_detect", YAML::Load("{estimate_pose: false}"));
  CameraImage img;
  img.encoding("mono8");
  img.width(32);
  img.height(32);
  img.data().assign(32 * 32, 200);
  append_stamp(img.header(), 111);
  det.feed("image", img);
  det.advance(std::chrono::milliseconds(5));
  det.step();
  const auto out = det.take<TagDetections>("tags").at(0);
  EXPECT_TRUE(out->detections().empty());
  ASSERT_EQ(out->header().stamps().size(), 2u);
  EXPECT_EQ(out->header().stamps()[0], 111u);
  EXPECT_EQ(out->header().stamps()[1], static_cast<unsigned long long>(det.now()));
}

// Seed 004 §2.4: the detector asks the coordinator for a closer look while a sign is in view and
// for closer_look_ms after; without closer_look_ms it never asks.
TEST(AprilTagDetect, AsksForACloserLookWhileTagsAreInView) {
  KernelHarness grab("framegrabber", YAML::Load("{source: 'synthetic:static'}"), "cam");
  CameraImage blank;
  blank.encoding("mono8");
  blank.width(64);
  blank.height(48);
  blank.data().assign(64 * 48, 0);
  for (const int hold_ms : {0, 200}) {
    KernelHarness det(
        "apriltag_detect",
        YAML::Load("{estimate_pose: false, closer_look_ms: " + std::to_string(hold_ms) + "}"),
        "door_search");
    const auto& wish = det.wish("closer_look");
    grab.step();
    det.feed("image", *grab.take<CameraImage>("frame").at(0));
    det.step();
    ASSERT_FALSE(det.take<TagDetections>("tags").at(0)->detections().empty());
    EXPECT_EQ(wish.asked(), hold_ms > 0) << "closer_look_ms " << hold_ms;
    det.advance(std::chrono::milliseconds(150));
    det.feed("image", blank);
    det.step();
    EXPECT_EQ(wish.asked(), hold_ms > 0) << "dropped before closer_look_ms passed";
    det.advance(std::chrono::milliseconds(100));
    det.feed("image", blank);
    det.step();
    EXPECT_FALSE(wish.asked()) << "still asked after closer_look_ms without a tag";
    EXPECT_FALSE(wish.granted()) << "granted without a coordinator";
  }
  KernelHarness det("apriltag_detect", YAML::Load("{}"), "door_search");
  EXPECT_THROW(det.wish("far_look"), std::invalid_argument);
}

TEST(AprilTagDetect, PoseWithoutIntrinsicsIsAClearErrorAndPublishesNothing) {
  KernelHarness det("apriltag_detect", YAML::Load("{}"), "mark_a");
  CameraImage img;
  img.camera_id("usb_cam");
  img.encoding("mono8");
  img.width(16);
  img.height(16);
  img.data().assign(256, 0);
  det.feed("image", img);
  EXPECT_THAT(error_of(det), HasSubstr("apriltag_detect 'mark_a': pose estimation needs "
                                       "intrinsics, but camera 'usb_cam' sends none"));
  EXPECT_EQ(det.take_count("tags"), 0u);
}

TEST(AprilTagDetect, ATagSizeSetToZeroWhileRunningIsAnErrorNotAZeroPose) {
  KernelHarness det("apriltag_detect", YAML::Load("{}"), "mark_a");
  det.instance().ports().params.set_text("tag_size_m", "0");
  CameraImage img;
  img.encoding("mono8");
  img.width(16);
  img.height(16);
  img.fx(10);
  img.fy(10);
  img.cx(8);
  img.cy(8);
  img.data().assign(256, 0);
  det.feed("image", img);
  EXPECT_THAT(error_of(det), HasSubstr("estimate_pose needs tag_size_m > 0"));
  EXPECT_EQ(det.take_count("tags"), 0u);
}

TEST(AprilTagDetect, AnImageThatIsNotMono8OfItsSizeIsAnError) {
  KernelHarness det("apriltag_detect", YAML::Load("{estimate_pose: false}"), "mark_a");
  CameraImage img;
  img.encoding("mono8");
  img.width(16);
  img.height(16);
  img.data().assign(100, 0);
  det.feed("image", img);
  EXPECT_THAT(error_of(det), HasSubstr("is not mono8 16x16 (100 bytes"));
  EXPECT_EQ(det.take_count("tags"), 0u);
}

TEST(AprilTagDetect, UnknownFamilyBadIdsAndMissingTagSizeAreRefused) {
  const auto refused = [](const std::string& yaml) {
    try {
      KernelHarness h("apriltag_detect", YAML::Load(yaml), "mark_a");
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const auto family = refused("{family: tag99h1}");
  EXPECT_THAT(family, HasSubstr("family"));
  EXPECT_THAT(family, HasSubstr("tag99h1"));
  EXPECT_THAT(family, HasSubstr("tag36h11"));
  EXPECT_THAT(refused("{ids: '1,x'}"), HasSubstr("'x' is not a tag id"));
  EXPECT_THAT(refused("{tag_size_m: 0}"), HasSubstr("estimate_pose needs tag_size_m > 0"));
  EXPECT_EQ(refused("{tag_size_m: 0, estimate_pose: false, family: tag25h9}"), "accepted");
}

TEST(AprilTagDetect, StubPublishesOnePlausibleTag) {
  KernelHarness det("apriltag_detect", YAML::Load("{ids: '5'}"));
  det.step_stub();
  const auto out = det.take<TagDetections>("tags").at(0);
  ASSERT_EQ(out->detections().size(), 1u);
  const auto& t = out->detections()[0];
  EXPECT_EQ(t.id(), 5);
  EXPECT_TRUE(t.has_pose());
  EXPECT_DOUBLE_EQ(t.center()[0], 320);
  EXPECT_GT(t.corners()[2], t.corners()[0]);  // corner 1 right of corner 0
}

}  // namespace
}  // namespace oscar

OSCAR_KERNEL_CONFORMANCE_TEST(AprilTagDetect, "apriltag_detect", "{}")
OSCAR_KERNEL_CONFORMANCE_TEST(AprilTagDetectNoPose, "apriltag_detect",
                              "{family: tag25h9, estimate_pose: false, ids: '0,2'}")
