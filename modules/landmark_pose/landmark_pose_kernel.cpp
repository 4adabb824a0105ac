#include "landmark_pose_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>

#include <fmt/format.h>

#include <oscar/kernel_registry.hpp>

#include "perception_geometry.hpp"

namespace oscar::modules {
namespace {
// How long after wait_b the fusion still waits for the producer's answer (it travels back).
constexpr std::chrono::milliseconds kAnswerSlack{50};
}  // namespace

void LandmarkPoseFusion::Params::describe(ParamSpec& spec) {
  spec.field("tag_layout", tag_layout, "tags on the target 'id:x,y,z;...' (target frame, m)");
  spec.field("max_skew", max_skew, "B's image may be this much older than A's (newer: any)")
      .at_least(0);
  spec.field("wait_b", wait_b,
             "pull/prefetch: how long B's frame holds the ask for this cycle's result")
      .range(0, static_cast<double>(kMaxPullWait.count()));
  spec.field("log_every", log_every, "log a summary this often (0 = never)").at_least(0);
}

LandmarkPoseFusion::LandmarkPoseFusion(KernelSetup& setup)
    : tags_a_(setup.input<TagDetections>("tags_a")),
      tags_b_(setup.input<TagDetections>("tags_b")),
      pose_(setup.output<oscar::LandmarkPose>("pose")) {
  setup.params(params_);
  on_params_changed();
}

void LandmarkPoseFusion::on_params_changed() {
  layout_.clear();
  for (const auto& t : parse_tag_layout(params_.tag_layout)) layout_[t.id] = t.offset_m;
}

// B's detections, if its image was taken at most max_skew before A's (on one host B's image is
// taken after A's; across hosts B is triggered first, just before A). With push they are in the
// ring already (on one host MarkBDetect runs before this kernel). With pull or prefetch (B on
// another host, seed 004 §4.2) B may still be working on this cycle's image: the producer holds
// the request until B's first result from an image at most max_skew older than A's is there, up
// to wait_b, and answers it then.
Input<TagDetections>::Ptr LandmarkPoseFusion::matching_b(Stamp acquired) {
  const Stamp oldest = acquired - params_.max_skew.count();
  if (tags_b_.transfer() == Transfer::kPush) {
    auto b = tags_b_.latest();
    return b && generation_stamp(b->header()) >= oldest ? b : nullptr;
  }
  // The producer answers (empty) when the wait is up; a little longer here covers the way back.
  return tags_b_.prefetch(PullQuery::kAtOrAfter, oldest, params_.wait_b)
      .get(params_.wait_b + kAnswerSlack);
}

void LandmarkPoseFusion::add_estimates(const TagDetections& tags,
                                       std::vector<Eigen::Isometry3d>& out,
                                       oscar::LandmarkPose& cue) const {
  const Eigen::Vector3d camera(tags.position()[0], tags.position()[1], tags.position()[2]);
  bool used = false;
  for (const auto& d : tags.detections()) {
    const auto it = layout_.find(d.id());
    if (!d.has_pose() || it == layout_.end()) continue;
    // target = tag * (tag in the target frame)^-1, moved from the camera into the world frame
    // (camera axes are parallel to the world's).
    Eigen::Isometry3d target = from_pose3(d.pose());
    target.translate(-it->second);
    target.pretranslate(camera);
    out.push_back(target);
    cue.tag_ids().push_back(d.id());
    used = true;
  }
  if (used) cue.cameras().push_back(tags.camera_id());
}

void LandmarkPoseFusion::process(Cycle& cycle) {
  const auto news = tags_a_.take_new();
  if (news.empty()) return;
  const auto& a = *news.back().cue;  // the newest image of A; older ones are superseded
  const auto asked = std::chrono::steady_clock::now();
  const auto b = matching_b(generation_stamp(a.header()));
  // The fused pose exists once B's result is here: with pull/prefetch that may be later than
  // the cycle's start, and the stamp says so.
  Stamp fused_at = cycle.now();
  if (tags_b_.transfer() != Transfer::kPush) {
    fused_at += std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::steady_clock::now() - asked)
                    .count();
  }
  oscar::LandmarkPose cue;
  cue.header() = a.header();
  cue.truth(a.truth());
  std::vector<Eigen::Isometry3d> estimates;
  add_estimates(a, estimates, cue);
  const auto from_a = estimates.size();
  if (b) {
    for (const auto s : b->header().stamps()) cue.header().stamps().push_back(s);
    add_estimates(*b, estimates, cue);
  } else {
    cycle.log().debug("no detections of B taken at most {} ms before A's image",
                      params_.max_skew.count() / 1e6);
  }
  cue.estimates(static_cast<std::uint32_t>(estimates.size()));
  cue.valid(!estimates.empty());
  if (!estimates.empty()) {
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    Eigen::Vector4d q = Eigen::Vector4d::Zero();
    const Eigen::Quaterniond first(estimates.front().rotation());
    for (const auto& e : estimates) {
      t += e.translation();
      Eigen::Quaterniond qi(e.rotation());
      if (qi.dot(first) < 0) qi.coeffs() *= -1;  // q and -q are one rotation
      q += qi.coeffs();
    }
    t /= static_cast<double>(estimates.size());
    Eigen::Isometry3d fused = Eigen::Isometry3d::Identity();
    fused.translate(t);
    fused.rotate(Eigen::Quaterniond(q.normalized()));
    double spread = 0;
    for (const auto& e : estimates) spread = std::max(spread, (e.translation() - t).norm());
    cue.pose(to_pose3(fused));
    cue.spread_m(spread);
  }
  append_stamp(cue.header(), fused_at);
  // What the fused pose should be: where the target was at A's grab, or, with B's estimates,
  // the mean of where it was at both grabs weighted as the estimates are (it moves in between).
  std::optional<Eigen::Vector3d> expected;
  if (a.truth().valid()) {
    expected = from_pose3(a.truth().target()).translation();
    const auto from_b = estimates.size() - from_a;
    if (from_b > 0 && b->truth().valid()) {
      const Eigen::Vector3d at_b = from_pose3(b->truth().target()).translation();
      *expected = (*expected * static_cast<double>(from_a) + at_b * static_cast<double>(from_b)) /
                  static_cast<double>(estimates.size());
    }
  }
  account(cue, expected, cycle);
  pose_.publish(std::move(cue));
}

void LandmarkPoseFusion::account(const oscar::LandmarkPose& cue,
                                 const std::optional<Eigen::Vector3d>& expected, Cycle& cycle) {
  if (params_.log_every.count() == 0) return;
  if (window_start_ == 0) window_start_ = cycle.now();
  ++poses_;
  if (cue.cameras().size() == 2) ++both_;
  const auto& st = cue.header().stamps();
  // Acquisition of the first image to the fused pose: stamps[0] is A's grab, B's grab follows
  // A's two stamps when B was used.
  Stamp acquired = static_cast<Stamp>(st.front());
  if (st.size() >= 5) acquired = std::min(acquired, static_cast<Stamp>(st[2]));
  latencies_ms_.push_back((static_cast<Stamp>(st.back()) - acquired) / 1e6);
  if (cue.valid() && expected) {
    ++truths_;
    const auto pose = from_pose3(cue.pose()), truth = from_pose3(cue.truth().target());
    worst_mm_ = std::max(worst_mm_, (pose.translation() - *expected).norm() * 1000);
    worst_deg_ = std::max(
        worst_deg_,
        Eigen::Quaterniond(pose.rotation()).angularDistance(Eigen::Quaterniond(truth.rotation())) *
            180 / M_PI);
  }
  const double window_s = (cycle.now() - window_start_) / 1e9;
  if (window_s * 1e9 < static_cast<double>(params_.log_every.count())) return;
  std::sort(latencies_ms_.begin(), latencies_ms_.end());
  const auto pct = [&](double p) {
    return latencies_ms_[std::min(latencies_ms_.size() - 1,
                                  static_cast<std::size_t>(p * latencies_ms_.size()))];
  };
  const auto truth = truths_ == 0 ? std::string("no ground truth")
                                  : fmt::format("vs ground truth worst {:.1f} mm {:.2f} deg",
                                                worst_mm_, worst_deg_);
  cycle.log().info(
      "{} poses in {:.1f} s ({:.1f}/s), {} from both cameras; acquisition->pose p50 {:.1f} ms "
      "p99 {:.1f} ms; {}",
      poses_, window_s, poses_ / window_s, both_, pct(0.5), pct(0.99), truth);
  window_start_ = cycle.now();
  poses_ = both_ = truths_ = 0;
  latencies_ms_.clear();
  worst_mm_ = worst_deg_ = 0;
}

// Stub: the target 0.7 m straight ahead, seen by two tags.
void LandmarkPoseFusion::stub(Cycle& cycle) {
  oscar::LandmarkPose cue;
  if (const auto a = tags_a_.latest()) cue.header() = a->header();
  cue.valid(true);
  cue.pose().t({0, 0, 0.7});
  cue.pose().q({1, 0, 0, 0});
  cue.estimates(2);
  for (const auto& [id, offset] : layout_) cue.tag_ids().push_back(id);
  append_stamp(cue.header(), cycle.now());
  pose_.publish(std::move(cue));
}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::LandmarkPoseFusion, "landmark_pose")
