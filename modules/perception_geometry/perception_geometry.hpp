#pragma once
/// @file Geometry shared by the perception modules: Pose3 <-> Eigen and the text forms of
/// vectors and tag layouts used in their parameters.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <oscar/perception_types.hpp>

namespace oscar::modules {

/// A tag on the synthetic target: its tag36h11 id and its centre in the target frame (metres).
struct TagPlacement {
  int id = 0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
};

/// "0:-0.08,0,0;1:0.08,0,0" -> placements. @throws std::invalid_argument naming the entry.
std::vector<TagPlacement> parse_tag_layout(const std::string& text);
/// "x,y,z" -> vector. @throws std::invalid_argument naming `what`.
Eigen::Vector3d parse_vector3(const std::string& text, const std::string& what);

/// Pose3 (IDL) <-> Eigen.
Pose3 to_pose3(const Eigen::Isometry3d& pose);
Eigen::Isometry3d from_pose3(const Pose3& pose);

}  // namespace oscar::modules
