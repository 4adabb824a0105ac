#include "synthetic_scene.hpp"

#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <apriltag/tag36h11.h>
#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace oscar::modules {
namespace {
constexpr int kCell = 8;  // bitmap pixels per tag cell

// The tag's cells -1..8 (white ring, black border, 6x6 payload) as a bitmap. Bit i of the code
// (most significant first) sits at cell (bit_x[i], bit_y[i]); 1 is white — how AprilTag 3
// decodes it.
cv::Mat tag_bitmap(const apriltag_family_t& family, int id) {
  const int cells = family.width_at_border + 2;
  cv::Mat cellmap(cells, cells, CV_8U, cv::Scalar(255));
  cellmap(cv::Rect(1, 1, family.width_at_border, family.width_at_border)).setTo(0);
  const std::uint64_t code = family.codes[id];
  for (std::uint32_t i = 0; i < family.nbits; ++i) {
    const bool white = ((code >> (family.nbits - 1 - i)) & 1u) != 0;
    cellmap.at<std::uint8_t>(static_cast<int>(family.bit_y[i]) + 1,
                             static_cast<int>(family.bit_x[i]) + 1) = white ? 255 : 0;
  }
  cv::Mat bitmap;
  cv::resize(cellmap, bitmap, {cells * kCell, cells * kCell}, 0, 0, cv::INTER_NEAREST);
  return bitmap;
}
}  // namespace

SyntheticScene::SyntheticScene(SceneOptions options) : options_(std::move(options)) {
  auto& o = options_;
  if (o.width < 16 || o.height < 16) throw std::invalid_argument("synthetic image too small");
  if (o.fx <= 0) o.fx = o.width;
  if (o.fy <= 0) o.fy = o.fx;
  if (o.cx <= 0) o.cx = o.width / 2.0;
  if (o.cy <= 0) o.cy = o.height / 2.0;
  std::unique_ptr<apriltag_family_t, void (*)(apriltag_family_t*)> family(tag36h11_create(),
                                                                          &tag36h11_destroy);
  for (const auto& t : o.tags) {
    if (t.id < 0 || static_cast<std::uint32_t>(t.id) >= family->ncodes) {
      throw std::invalid_argument(
          fmt::format("tag id {} is not in tag36h11 (0..{})", t.id, family->ncodes - 1));
    }
    bitmaps_.push_back(tag_bitmap(*family, t.id));
  }
}

SyntheticScene::~SyntheticScene() = default;

Eigen::Isometry3d SyntheticScene::target_pose(std::uint64_t frame) const {
  const auto& o = options_;
  const double t = o.moving ? static_cast<double>(frame) / o.scene_fps : o.motion_period_s / 8;
  const double w = 2 * M_PI / o.motion_period_s;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(0.05 * std::sin(w * t), 0.03 * std::sin(2 * w * t),
                                 o.distance_m + 0.1 * std::sin(w * t + 1)));
  const double deg = M_PI / 180;
  pose.rotate(Eigen::AngleAxisd(25 * deg * std::sin(w * t), Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(15 * deg * std::sin(0.7 * w * t + 0.5), Eigen::Vector3d::UnitX()) *
              Eigen::AngleAxisd(10 * deg * std::sin(0.3 * w * t), Eigen::Vector3d::UnitZ()));
  return pose;
}

cv::Mat SyntheticScene::render(std::uint64_t frame, GroundTruth& truth) const {
  const auto& o = options_;
  cv::Mat image(o.height, o.width, CV_8U);
  for (int y = 0; y < o.height; ++y) {  // a soft gradient, so the background is not flat
    image.row(y).setTo(static_cast<int>(70 + 60.0 * y / o.height));
  }
  const Eigen::Isometry3d target = target_pose(frame);
  truth.valid(true);
  truth.target(to_pose3(target));
  truth.tags().clear();
  Eigen::Matrix3d k;
  k << o.fx, 0, o.cx, 0, o.fy, o.cy, 0, 0, 1;
  const double half = o.tag_size_m / 2;
  // Bitmap pixel (OpenCV: centre at integers) -> tag coordinates in [-1, 1] (cell c centre at
  // (c + 0.5) / 4 - 1, AprilTag's sampling of a tag 8 cells wide at the border).
  Eigen::Matrix3d to_tag;
  const double a = 1.0 / (4.0 * kCell), b = (0.5 / kCell - 1) / 4 - 1;
  to_tag << a, 0, b, 0, a, b, 0, 0, 1;
  Eigen::Matrix3d to_opencv;  // AprilTag pixel i spans [i, i+1): OpenCV's centre is i
  to_opencv << 1, 0, -0.5, 0, 1, -0.5, 0, 0, 1;
  for (std::size_t i = 0; i < o.tags.size(); ++i) {
    Eigen::Isometry3d tag = target;
    tag.translate(o.tags[i].offset_m);
    tag.pretranslate(-o.camera_position_m);  // into the camera frame (axes parallel)
    if (tag.translation().z() < 0.05) continue;
    Eigen::Matrix3d rt;  // tag coordinates (x, y) -> camera point (x s/2, y s/2, 0) + t
    rt.col(0) = tag.rotation().col(0) * half;
    rt.col(1) = tag.rotation().col(1) * half;
    rt.col(2) = tag.translation();
    const Eigen::Matrix3d h = k * rt;
    TagTruth tt;
    tt.id(o.tags[i].id);
    tt.pose(to_pose3(tag));
    const double cx[4] = {-1, 1, 1, -1}, cy[4] = {1, 1, -1, -1};  // AprilTag's corner order
    bool inside = true;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d p = h * Eigen::Vector3d(cx[c], cy[c], 1);
      tt.corners()[2 * c] = p.x() / p.z();
      tt.corners()[2 * c + 1] = p.y() / p.z();
      inside = inside && tt.corners()[2 * c] > 1 && tt.corners()[2 * c] < o.width - 1 &&
               tt.corners()[2 * c + 1] > 1 && tt.corners()[2 * c + 1] < o.height - 1;
    }
    const Eigen::Matrix3d m = to_opencv * h * to_tag;
    cv::Mat cvm(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) cvm.at<double>(r, c) = m(r, c);
    }
    cv::warpPerspective(bitmaps_[i], image, cvm, image.size(), cv::INTER_LINEAR,
                        cv::BORDER_TRANSPARENT);
    if (inside) truth.tags().push_back(tt);
  }
  if (o.blur_sigma_px > 0) cv::GaussianBlur(image, image, {0, 0}, o.blur_sigma_px);
  if (o.noise_sigma > 0) {
    cv::RNG rng(o.seed * 1'000'003 + frame);
    cv::Mat noise(image.size(), CV_16S);
    rng.fill(noise, cv::RNG::NORMAL, 0, o.noise_sigma);
    cv::Mat sum;
    image.convertTo(sum, CV_16S);
    sum += noise;
    sum.convertTo(image, CV_8U);  // saturates
  }
  return image;
}

}  // namespace oscar::modules
