#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <oscar/command_types.hpp>
#include <oscar/cue_types.hpp>
#include <oscar/harness.hpp>
#include <oscar/perception_types.hpp>
#include <oscar/testing/conformance.hpp>

namespace oscar {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string error_of(KernelHarness& h) {
  try {
    h.step();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

fs::path temp_dir(const std::string& name) {
  const auto dir = fs::temp_directory_path() / (name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(Framegrabber, SyntheticFramesCarryImageIntrinsicsAndGroundTruth) {
  KernelHarness h("framegrabber", YAML::Load("{source: synthetic:moving}"), "cam_a");
  h.step();
  const auto frames = h.take<CameraImage>("frame");
  const auto images = h.take<GvImage>("image");
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(images.size(), 1u);
  const auto& f = *frames[0];
  EXPECT_EQ(f.camera_id(), "cam_a");
  EXPECT_EQ(f.width(), 640);
  EXPECT_EQ(f.height(), 480);
  EXPECT_EQ(f.data().size(), 640u * 480u);
  EXPECT_DOUBLE_EQ(f.fx(), 640);
  EXPECT_DOUBLE_EQ(f.cx(), 320);
  EXPECT_TRUE(f.truth().valid());
  ASSERT_EQ(f.truth().tags().size(), 2u);
  EXPECT_EQ(images[0]->dx(), 640);
  EXPECT_EQ(images[0]->image(), f.data());
}

TEST(Framegrabber, TheMovingSceneMovesAndTheStaticOneDoesNot) {
  for (const std::string scene : {"moving", "static"}) {
    KernelHarness h("framegrabber", YAML::Load("{source: synthetic:" + scene + "}"));
    h.step();
    h.step();
    const auto frames = h.take<CameraImage>("frame");
    ASSERT_EQ(frames.size(), 2u);
    const bool same = frames[0]->truth().target().t() == frames[1]->truth().target().t();
    EXPECT_EQ(same, scene == "static") << scene;
  }
}

TEST(Framegrabber, FrameModeSetAtRunTimeChangesTheImageSizeAndIntrinsics) {
  KernelHarness h("framegrabber", YAML::Load("{source: synthetic}"));
  for (const auto& [mode, w, hh] : {std::tuple{"half", 320, 240}, std::tuple{"quarter", 160, 120},
                                    std::tuple{"full", 640, 480}}) {
    h.instance().ports().params.set_text("frame_mode", mode);
    h.step();
    const auto f = h.take<CameraImage>("frame").at(0);
    EXPECT_EQ(f->width(), w) << mode;
    EXPECT_EQ(f->height(), hh) << mode;
    EXPECT_DOUBLE_EQ(f->fx(), 640.0 * w / 640) << mode;
    EXPECT_EQ(h.take<GvImage>("image").at(0)->dy(), hh) << mode;
  }
}

SetFrameMode frame_mode(const std::string& mode) {
  SetFrameMode request;
  request.mode(mode);
  return request;
}

TEST(Framegrabber, TheFrameModeCommandSetsTheFrameSizeAndTheLaterOfCommandAndParameterWins) {
  KernelHarness h("framegrabber", YAML::Load("{source: synthetic}"));
  const auto answer = h.command("frame_mode", frame_mode("half"));
  EXPECT_TRUE(answer.accepted);
  EXPECT_EQ(answer.text, "frame mode full -> half");
  h.step();
  EXPECT_EQ(h.take<CameraImage>("frame").at(0)->width(), 320);
  h.instance().ports().params.set_text("frame_mode", "quarter");  // set_param after the command
  h.step();
  EXPECT_EQ(h.take<CameraImage>("frame").at(0)->width(), 160);
  EXPECT_TRUE(h.command("frame_mode", frame_mode("full")).accepted);  // and a command after that
  h.step();
  EXPECT_EQ(h.take<CameraImage>("frame").at(0)->width(), 640);
}

TEST(Framegrabber, TheFrameModeCommandRefusesAnUnknownModeAndKeepsItsMode) {
  KernelHarness h("framegrabber", YAML::Load("{source: synthetic, frame_mode: half}"));
  const auto answer = h.command("frame_mode", frame_mode("eighth"));
  EXPECT_FALSE(answer.accepted);
  EXPECT_EQ(answer.text, "frame mode 'eighth' is not full, half or quarter");
  h.step();
  EXPECT_EQ(h.take<CameraImage>("frame").at(0)->width(), 320);
}

TEST(Framegrabber, ReadsAnImageDirectoryInNameOrderAndLoops) {
  const auto dir = temp_dir("fg_dir");
  for (int i = 0; i < 3; ++i) {
    cv::imwrite((dir / fmt::format("f{}.png", i)).string(),
                cv::Mat(20 + i, 30, CV_8U, cv::Scalar(10 * i)));
  }
  KernelHarness h("framegrabber", YAML::Load("{source: 'dir:" + dir.string() + "'}"));
  for (int i = 0; i < 4; ++i) h.step();
  const auto frames = h.take<CameraImage>("frame");
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0]->height(), 20);
  EXPECT_EQ(frames[2]->height(), 22);
  EXPECT_EQ(frames[3]->height(), 20);  // looped
  EXPECT_EQ(frames[1]->data()[0], 10);
  EXPECT_FALSE(frames[0]->truth().valid());
  EXPECT_EQ(frames[0]->fx(), 0);  // unknown intrinsics stay unknown
  fs::remove_all(dir);
}

TEST(Framegrabber, ANonLoopingDirectoryStopsPublishingAtItsEnd) {
  const auto dir = temp_dir("fg_end");
  cv::imwrite((dir / "a.png").string(), cv::Mat(8, 8, CV_8U, cv::Scalar(1)));
  KernelHarness h("framegrabber", YAML::Load("{source: 'dir:" + dir.string() + "', loop: false}"));
  h.step();
  h.step();
  EXPECT_EQ(h.take_count("frame"), 1u);
  fs::remove_all(dir);
}

TEST(Framegrabber, AnUnreadableImageIsAnErrorNamingTheFile) {
  const auto dir = temp_dir("fg_bad");
  std::ofstream(dir / "broken.png") << "not a png";
  KernelHarness h("framegrabber", YAML::Load("{source: 'dir:" + dir.string() + "'}"));
  EXPECT_THAT(error_of(h), HasSubstr("unreadable image '" + (dir / "broken.png").string() + "'"));
  EXPECT_EQ(h.take_count("frame"), 0u);  // nothing published
  fs::remove_all(dir);
}

TEST(Framegrabber, MissingDeviceFileOrDirectoryAreClearErrors) {
  KernelHarness dev("framegrabber", YAML::Load("{source: 'v4l2:/dev/video_oscar_none'}"), "cam");
  EXPECT_THAT(error_of(dev),
              HasSubstr("framegrabber 'cam': video device '/dev/video_oscar_none' does not exist"));
  KernelHarness file("framegrabber", YAML::Load("{source: 'file:/nonexistent/x.avi'}"));
  EXPECT_THAT(error_of(file), HasSubstr("video file '/nonexistent/x.avi' does not exist"));
  KernelHarness dir("framegrabber", YAML::Load("{source: 'dir:/nonexistent/frames'}"));
  EXPECT_THAT(error_of(dir), HasSubstr("image directory '/nonexistent/frames' does not exist"));
  const auto empty = temp_dir("fg_empty");
  KernelHarness none("framegrabber", YAML::Load("{source: 'dir:" + empty.string() + "'}"));
  EXPECT_THAT(error_of(none), HasSubstr("holds no images"));
  EXPECT_EQ(dev.take_count("frame") + file.take_count("frame") + dir.take_count("frame") +
                none.take_count("frame"),
            0u);
  fs::remove_all(empty);
}

TEST(Framegrabber, AFileThatIsNoVideoIsAClearError) {
  const auto dir = temp_dir("fg_novideo");
  std::ofstream(dir / "x.avi") << "garbage";
  KernelHarness h("framegrabber", YAML::Load("{source: 'file:" + (dir / "x.avi").string() + "'}"));
  EXPECT_THAT(error_of(h), HasSubstr("cannot open video file"));
  fs::remove_all(dir);
}

TEST(Framegrabber, BadSourcesAndLayoutsAreRefusedAtConstruction) {
  const auto refused = [](const std::string& yaml) {
    try {
      KernelHarness h("framegrabber", YAML::Load(yaml));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(refused("{source: 'usb:0'}"),
              HasSubstr("expected v4l2:/dev/videoN, file:PATH, dir:PATH or synthetic"));
  EXPECT_THAT(refused("{source: 'synthetic:wobbly'}"), HasSubstr("'moving' or 'static'"));
  EXPECT_THAT(refused("{source: 'file:'}"), HasSubstr("names no path"));
  EXPECT_THAT(refused("{tag_layout: '0:1,2'}"), HasSubstr("is not 'x,y,z'"));
  EXPECT_THAT(refused("{frame_mode: eighth}"), HasSubstr("frame_mode"));
}

TEST(Framegrabber, StubPublishesAFlatFrameWithoutTags) {
  KernelHarness h("framegrabber", YAML::Load("{width: 64, height: 48}"));
  h.step_stub();
  const auto f = h.take<CameraImage>("frame").at(0);
  EXPECT_EQ(f->width(), 64);
  EXPECT_EQ(f->data().at(100), 128);
  EXPECT_FALSE(f->truth().valid());
  EXPECT_EQ(h.take_count("image"), 1u);
}

}  // namespace
}  // namespace oscar

OSCAR_KERNEL_CONFORMANCE_TEST(FramegrabberSynthetic, "framegrabber", "{source: synthetic}")
OSCAR_KERNEL_CONFORMANCE_TEST(FramegrabberStaticHalf, "framegrabber",
                              "{source: 'synthetic:static', frame_mode: half}")
