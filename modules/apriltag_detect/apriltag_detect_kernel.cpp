#include "apriltag_detect_kernel.hpp"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>
#include <fmt/format.h>
#include <Eigen/Geometry>

#include <oscar/kernel_registry.hpp>

namespace oscar::modules {
namespace {
struct FamilyEntry {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};
const FamilyEntry kFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag36h10", tag36h10_create, tag36h10_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
};

const FamilyEntry& family_entry(const std::string& name) {
  for (const auto& f : kFamilies) {
    if (name == f.name) return f;
  }
  throw std::invalid_argument(fmt::format("unknown tag family '{}'", name));
}

std::vector<int> parse_ids(const std::string& text) {
  std::vector<int> ids;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');) {
    std::size_t used = 0;
    int id = -1;
    try {
      id = std::stoi(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size() || id < 0) {
      throw std::invalid_argument(fmt::format(
          "parameter 'ids': '{}' is not a tag id (expected '' or ids like '0,3')", part));
    }
    ids.push_back(id);
  }
  return ids;
}
}  // namespace

// The AprilTag detector and its family, created on activation (they allocate).
struct AprilTagDetect::Detector {
  Detector(const Params& p) : entry(family_entry(p.family)) {
    family = entry.create();
    td = apriltag_detector_create();
    apriltag_detector_add_family_bits(td, family, p.max_hamming);
    td->nthreads = 1;
    td->quad_decimate = static_cast<float>(p.decimate);
    td->quad_sigma = static_cast<float>(p.blur_sigma);
    td->refine_edges = p.refine_edges;
  }
  ~Detector() {
    apriltag_detector_destroy(td);
    entry.destroy(family);
  }
  const FamilyEntry& entry;
  apriltag_family_t* family = nullptr;
  apriltag_detector_t* td = nullptr;
  std::vector<std::uint8_t> pixels;  // AprilTag may write into the image it is given
};

const std::vector<std::string>& AprilTagDetect::families() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& f : kFamilies) n.emplace_back(f.name);
    return n;
  }();
  return names;
}

void AprilTagDetect::Params::describe(ParamSpec& spec) {
  spec.field("family", family, "AprilTag family").one_of(families()).fixed();
  spec.field("ids", ids, "keep only these ids, e.g. '0,3' ('' = all)");
  spec.field("estimate_pose", estimate_pose, "estimate each tag's pose (needs intrinsics)");
  spec.field("tag_size_m", tag_size_m, "tag edge (black border), m").at_least(0);
  spec.field("fx", fx, "focal length x, px (0 = the image's)").at_least(0);
  spec.field("fy", fy, "focal length y, px (0 = the image's)").at_least(0);
  spec.field("cx", cx, "principal point x, px (0 = the image's)").at_least(0);
  spec.field("cy", cy, "principal point y, px (0 = the image's)").at_least(0);
  spec.field("max_hamming", max_hamming, "bit errors corrected").range(0, 3).fixed();
  spec.field("decimate", decimate, "quad detection on an image decimated by this")
      .range(1, 8)
      .fixed();
  spec.field("blur_sigma", blur_sigma, "Gaussian blur before quad detection, px")
      .range(0, 10)
      .fixed();
  spec.field("refine_edges", refine_edges, "snap quad edges to strong gradients").fixed();
  spec.field("min_margin", min_margin, "drop detections with a lower decision margin").at_least(0);
  spec.field("closer_look_ms", closer_look_ms,
             "ask for the wish closer_look while tags are in view and this long after (0 = never)")
      .at_least(0);
}

AprilTagDetect::AprilTagDetect(KernelSetup& setup)
    : image_(setup.input<CameraImage>("image")),
      tags_(setup.output<TagDetections>("tags")),
      closer_look_(setup.wish("closer_look")) {
  setup.params(params_);
  name_ = setup.kernel_name();
  on_params_changed();
}

AprilTagDetect::~AprilTagDetect() = default;

void AprilTagDetect::on_params_changed() {
  ids_ = parse_ids(params_.ids);
  if (params_.estimate_pose && params_.tag_size_m <= 0) {
    throw std::invalid_argument(fmt::format(
        "apriltag_detect '{}': estimate_pose needs tag_size_m > 0 (the tag's edge in metres)",
        name_));
  }
}

void AprilTagDetect::on_activate() {
  if (!detector_) detector_ = std::make_unique<Detector>(params_);
}

void AprilTagDetect::on_deactivate() {
  detector_.reset();
  closer_look_.drop();
}

// Seed 004 §2.4: a module may tell the coordinator what it would like; here a sign in view would
// be read better with more pixels. Whether the wish is granted is the plan's decision.
void AprilTagDetect::wish_closer_look(bool tags_in_view, Stamp now) {
  if (params_.closer_look_ms <= 0) {
    closer_look_.drop();
    return;
  }
  if (tags_in_view) {
    last_tag_seen_ = now;
    closer_look_.ask();
  } else if (now - last_tag_seen_ > static_cast<Stamp>(params_.closer_look_ms) * 1'000'000) {
    closer_look_.drop();
  }
}

void AprilTagDetect::process(Cycle& cycle) {
  for (const auto& r : image_.take_new()) detect(*r.cue, cycle);
}

void AprilTagDetect::detect(const CameraImage& image, Cycle& cycle) {
  const std::size_t w = image.width(), h = image.height();
  if (image.encoding() != "mono8" || image.data().size() != w * h || w == 0 || h == 0) {
    throw std::runtime_error(fmt::format(
        "apriltag_detect '{}': image from camera '{}' is not mono8 {}x{} ({} bytes, encoding '{}')",
        name_, image.camera_id(), w, h, image.data().size(), image.encoding()));
  }
  apriltag_detection_info_t info{};
  if (params_.estimate_pose && params_.tag_size_m <= 0) {  // set to 0 while running
    throw std::runtime_error(fmt::format(
        "apriltag_detect '{}': estimate_pose needs tag_size_m > 0 (the tag's edge in metres)",
        name_));
  }
  if (params_.estimate_pose) {
    info.tagsize = params_.tag_size_m;
    info.fx = params_.fx > 0 ? params_.fx : image.fx();
    info.fy = params_.fy > 0 ? params_.fy : image.fy();
    info.cx = params_.cx > 0 ? params_.cx : image.cx();
    info.cy = params_.cy > 0 ? params_.cy : image.cy();
    if (info.fx <= 0 || info.fy <= 0 || info.cx <= 0 || info.cy <= 0) {
      throw std::runtime_error(fmt::format(
          "apriltag_detect '{}': pose estimation needs intrinsics, but camera '{}' sends none "
          "and the parameters fx, fy, cx, cy are not set (or set estimate_pose: false)",
          name_, image.camera_id()));
    }
  }
  on_activate();
  auto& d = *detector_;
  d.pixels.assign(image.data().begin(), image.data().end());
  image_u8_t im{static_cast<int32_t>(w), static_cast<int32_t>(h), static_cast<int32_t>(w),
                d.pixels.data()};
  zarray_t* found = apriltag_detector_detect(d.td, &im);
  TagDetections out;
  out.header() = image.header();
  out.camera_id(image.camera_id());
  out.width(image.width());
  out.height(image.height());
  out.position(image.position());
  out.truth(image.truth());
  for (int i = 0; i < zarray_size(found); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(found, i, &det);
    if (!ids_.empty() && std::find(ids_.begin(), ids_.end(), det->id) == ids_.end()) continue;
    if (det->decision_margin < params_.min_margin) continue;
    TagDetection t;
    t.family(params_.family);
    t.id(det->id);
    t.hamming(det->hamming);
    t.decision_margin(det->decision_margin);
    for (int c = 0; c < 4; ++c) {
      t.corners()[2 * c] = det->p[c][0];
      t.corners()[2 * c + 1] = det->p[c][1];
    }
    t.center({det->c[0], det->c[1]});
    for (int k = 0; k < 9; ++k) t.homography()[k] = det->H->data[k];
    if (params_.estimate_pose) {
      info.det = det;
      apriltag_pose_t pose{};
      t.pose_error(estimate_tag_pose(&info, &pose));
      Eigen::Matrix3d r;
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) r(row, col) = MATD_EL(pose.R, row, col);
      }
      const Eigen::Quaterniond q(r);
      t.pose().t({MATD_EL(pose.t, 0, 0), MATD_EL(pose.t, 1, 0), MATD_EL(pose.t, 2, 0)});
      t.pose().q({q.w(), q.x(), q.y(), q.z()});
      t.has_pose(true);
      // Debian's libapriltag exports no matd_destroy; a matd_t is one calloc'd block (its data
      // is a flexible array member), which is all matd_destroy frees.
      std::free(pose.R);
      std::free(pose.t);
    }
    out.detections().push_back(std::move(t));
  }
  apriltag_detections_destroy(found);
  wish_closer_look(!out.detections().empty(), cycle.now());
  append_stamp(out.header(), cycle.now());
  tags_.publish(std::move(out));
}

// Stub: one plausible tag (the first wanted id) in the middle of the newest image (or of a
// 640x480 one), facing the camera 1 m away.
void AprilTagDetect::stub(Cycle& cycle) {
  TagDetections out;
  std::uint16_t w = 640, h = 480;
  if (const auto img = image_.latest()) {
    out.header() = img->header();
    out.camera_id(img->camera_id());
    w = img->width();
    h = img->height();
  }
  out.width(w);
  out.height(h);
  TagDetection t;
  t.family(params_.family);
  t.id(ids_.empty() ? 0 : ids_.front());
  t.decision_margin(100);
  const double cx = w / 2.0, cy = h / 2.0, r = w / 16.0;
  t.corners({cx - r, cy + r, cx + r, cy + r, cx + r, cy - r, cx - r, cy - r});
  t.center({cx, cy});
  t.homography({r, 0, cx, 0, r, cy, 0, 0, 1});
  t.has_pose(params_.estimate_pose);
  t.pose().t({0, 0, 1});
  t.pose().q({1, 0, 0, 0});
  out.detections().push_back(t);
  append_stamp(out.header(), cycle.now());
  tags_.publish(std::move(out));
}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::AprilTagDetect, "apriltag_detect")
