#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <oscar/perception_types.hpp>

#include "perception_geometry.hpp"

namespace oscar::modules {

struct SceneOptions {
  int width = 640, height = 480;
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< 0: fx = fy = width, principal point in the middle
  std::vector<TagPlacement> tags;
  double tag_size_m = 0.1;
  double distance_m = 0.7;
  bool moving = true;
  double motion_period_s = 4.0;
  double scene_fps = 10.0;  ///< frame k shows the scene at time k / scene_fps
  double noise_sigma = 0;   ///< grey levels
  double blur_sigma_px = 0;
  std::uint64_t seed = 1;
  Eigen::Vector3d camera_position_m = Eigen::Vector3d::Zero();
};

/// Renders a target carrying tag36h11 markers at a known, moving pose through a pinhole camera
/// (axes parallel to the world's: x right, y down, z forward), so tests know the ground truth.
class SyntheticScene {
 public:
  /// @throws std::invalid_argument for ids outside tag36h11 or bad sizes.
  explicit SyntheticScene(SceneOptions options);
  ~SyntheticScene();
  SyntheticScene(const SyntheticScene&) = delete;
  SyntheticScene& operator=(const SyntheticScene&) = delete;

  /// The target's pose in the world frame at frame k.
  Eigen::Isometry3d target_pose(std::uint64_t frame) const;
  /// The full-size mono8 image of frame k and its ground truth.
  cv::Mat render(std::uint64_t frame, GroundTruth& truth) const;
  const SceneOptions& options() const { return options_; }
  /// Noise and blur may change while the scene runs.
  void set_degradation(double noise_sigma, double blur_sigma_px) {
    options_.noise_sigma = noise_sigma;
    options_.blur_sigma_px = blur_sigma_px;
  }

 private:
  SceneOptions options_;
  std::vector<cv::Mat> bitmaps_;  // one per tag, cells of kCell pixels, white ring included
};

}  // namespace oscar::modules
