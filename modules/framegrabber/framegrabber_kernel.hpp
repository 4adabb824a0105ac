#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <oscar/command_types.hpp>
#include <oscar/cue_types.hpp>
#include <oscar/kernel.hpp>
#include <oscar/perception_types.hpp>

#include "frame_source.hpp"
#include "synthetic_scene.hpp"

namespace oscar::modules {

/// Grabs grey images from a V4L2 camera, a video file, an image directory or a synthetic scene
/// of AprilTag markers with known poses (seed 004 §4.2: the framegrabber modules), in full,
/// half or quarter frame mode (seed 004 §4.2, MARVIN's framegrabber), switched by the parameter
/// `frame_mode` or the command `frame_mode`.
class Framegrabber final : public Kernel {
 public:
  struct Params {
    std::string source = "synthetic:moving";
    std::string camera_id;  ///< "" = the kernel's name
    std::string frame_mode = "full";
    bool loop = true;
    int width = 640, height = 480;          ///< synthetic image size (full frame)
    double fx = 0, fy = 0, cx = 0, cy = 0;  ///< full-frame intrinsics, pixels; 0 = unknown
    std::string position_m = "0,0,0";       ///< camera centre in the world frame
    std::string tag_layout = "0:-0.08,0,0;1:0.08,0,0";
    double tag_size_m = 0.1;
    double distance_m = 0.7;
    double motion_period_s = 4.0;
    double scene_fps = 10.0;
    double noise_sigma = 0;
    double blur_sigma_px = 0;
    int seed = 1;
    void describe(ParamSpec& spec);
  };
  explicit Framegrabber(KernelSetup& setup);
  ~Framegrabber() override;
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  void on_activate() override;
  void on_deactivate() override;

 private:
  void open();
  CommandAnswer set_frame_mode(const SetFrameMode& request);
  const std::string& frame_mode();
  void publish(const cv::Mat& full, GroundTruth truth, Stamp acquired);

  Output<GvImage>& image_;
  Output<CameraImage>& frame_;
  Params params_;
  std::string name_;
  SourceSpec source_;
  Eigen::Vector3d position_;
  std::unique_ptr<FrameSource> camera_;
  std::unique_ptr<SyntheticScene> scene_;
  struct Intrinsics {
    double fx = 0, fy = 0, cx = 0, cy = 0;  ///< full frame, px; 0 = unknown
  } intrinsics_;  ///< the parameters', or the synthetic scene's defaults for those left 0
  std::uint64_t frames_ = 0;
  bool ended_ = false;
  std::string frame_mode_;        // what it grabs: the parameter or the command, the later one
  std::string param_frame_mode_;  // the parameter as last seen
};

}  // namespace oscar::modules
