#include "perception_geometry.hpp"

#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar::modules {
namespace {
double parse_double(const std::string& s, const std::string& what) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != s.size()) {
    throw std::invalid_argument(fmt::format("{}: '{}' is not a number", what, s));
  }
  return v;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string part; std::getline(in, part, sep);) out.push_back(part);
  return out;
}

}  // namespace

Eigen::Vector3d parse_vector3(const std::string& text, const std::string& what) {
  const auto parts = split(text, ',');
  if (parts.size() != 3) {
    throw std::invalid_argument(fmt::format("{}: '{}' is not 'x,y,z'", what, text));
  }
  return {parse_double(parts[0], what), parse_double(parts[1], what), parse_double(parts[2], what)};
}

std::vector<TagPlacement> parse_tag_layout(const std::string& text) {
  std::vector<TagPlacement> out;
  for (const auto& entry : split(text, ';')) {
    const auto colon = entry.find(':');
    if (colon == std::string::npos) {
      throw std::invalid_argument(
          fmt::format("tag layout entry '{}': expected 'id:x,y,z' (metres)", entry));
    }
    TagPlacement p;
    p.id = static_cast<int>(parse_double(entry.substr(0, colon), "tag layout id"));
    p.offset_m =
        parse_vector3(entry.substr(colon + 1), fmt::format("tag layout entry '{}'", entry));
    out.push_back(p);
  }
  if (out.empty()) throw std::invalid_argument("tag layout: no tags ('id:x,y,z;...')");
  return out;
}

Pose3 to_pose3(const Eigen::Isometry3d& pose) {
  Pose3 p;
  const Eigen::Quaterniond q(pose.rotation());
  p.t({pose.translation().x(), pose.translation().y(), pose.translation().z()});
  p.q({q.w(), q.x(), q.y(), q.z()});
  return p;
}

Eigen::Isometry3d from_pose3(const Pose3& pose) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translate(Eigen::Vector3d(pose.t()[0], pose.t()[1], pose.t()[2]));
  out.rotate(Eigen::Quaterniond(pose.q()[0], pose.q()[1], pose.q()[2], pose.q()[3]).normalized());
  return out;
}

}  // namespace oscar::modules
