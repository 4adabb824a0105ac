#pragma once

#include <memory>
#include <string>
#include <vector>

#include <oscar/kernel.hpp>
#include <oscar/perception_types.hpp>

namespace oscar::modules {

/// Detects AprilTags in camera images with the AprilTag 3 library and, given intrinsics and
/// the tag size, estimates each tag's pose (seed 004 §4.2: MarkADetect and MarkBDetect).
class AprilTagDetect final : public Kernel {
 public:
  struct Params {
    std::string family = "tag36h11";
    std::string ids;  ///< "" = every id; else "0,3": keep only these
    bool estimate_pose = true;
    double tag_size_m = 0.1;                ///< edge of the black border
    double fx = 0, fy = 0, cx = 0, cy = 0;  ///< 0 = take the image's intrinsics
    int max_hamming = 1;
    double decimate = 1.0;
    double blur_sigma = 0.0;
    bool refine_edges = true;
    double min_margin = 0.0;  ///< drop detections with a lower decision margin
    /// > 0: ask for the wish `closer_look` while tags are in view and this long after the last
    /// (e.g. the camera in half frames, as the system file's `coordinator: wishes:` says).
    int closer_look_ms = 0;
    void describe(ParamSpec& spec);
  };
  /// The tag families this kernel knows (AprilTag 3's).
  static const std::vector<std::string>& families();

  explicit AprilTagDetect(KernelSetup& setup);
  ~AprilTagDetect() override;
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  void on_activate() override;
  void on_deactivate() override;
  void on_params_changed() override;

 private:
  struct Detector;
  void detect(const CameraImage& image, Cycle& cycle);
  void wish_closer_look(bool tags_in_view, Stamp now);

  Input<CameraImage>& image_;
  Output<TagDetections>& tags_;
  Wish& closer_look_;
  Stamp last_tag_seen_ = 0;
  Params params_;
  std::string name_;
  std::vector<int> ids_;
  std::unique_ptr<Detector> detector_;
};

}  // namespace oscar::modules
