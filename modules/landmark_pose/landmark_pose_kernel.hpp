#pragma once

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <oscar/kernel.hpp>
#include <oscar/perception_types.hpp>

namespace oscar::modules {

/// Fuses the tag poses of two detectors (MarkADetect, MarkBDetect; seed 004 §4.2) into one
/// estimate of the target's pose in the world frame. Its cue carries the stamps of both inputs
/// and its own (a fusing module extends the stamp sequence, seed 004 Abb. 3).
class LandmarkPoseFusion final : public Kernel {
 public:
  struct Params {
    std::string tag_layout = "0:-0.08,0,0;1:0.08,0,0";  ///< tag id : centre in the target frame
    std::chrono::nanoseconds max_skew{std::chrono::milliseconds(30)};
    std::chrono::nanoseconds wait_b{std::chrono::milliseconds(200)};
    std::chrono::nanoseconds log_every{std::chrono::seconds(1)};  ///< 0 = no summary
    void describe(ParamSpec& spec);
  };
  explicit LandmarkPoseFusion(KernelSetup& setup);
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  void on_params_changed() override;

 private:
  Input<TagDetections>::Ptr matching_b(Stamp acquired);
  void account(const oscar::LandmarkPose& cue, const std::optional<Eigen::Vector3d>& expected,
               Cycle& cycle);
  void add_estimates(const TagDetections& tags, std::vector<Eigen::Isometry3d>& out,
                     oscar::LandmarkPose& cue) const;

  Input<TagDetections>& tags_a_;
  Input<TagDetections>& tags_b_;
  Output<oscar::LandmarkPose>& pose_;
  Params params_;
  std::map<int, Eigen::Vector3d> layout_;
  // The periodic summary (log_every): poses, latencies acquisition -> pose, truth errors.
  Stamp window_start_ = 0;
  std::uint64_t poses_ = 0, both_ = 0, truths_ = 0;
  std::vector<double> latencies_ms_;
  double worst_mm_ = 0, worst_deg_ = 0;
};

}  // namespace oscar::modules
