#include "image_throttle.hpp"

namespace oscar::bridge {

bool is_image_schema(const std::string& schema_name) {
  return schema_name == "oscar::GvImage" || schema_name == "oscar::PlainGvImage" ||
         schema_name == "oscar::CameraImage" || schema_name == "foxglove.RawImage" ||
         schema_name == "foxglove.CompressedImage";
}

ImageThrottle::ImageThrottle(double images_per_second) {
  if (images_per_second > 0) {
    min_gap_ns_ = static_cast<std::uint64_t>(0.9e9 / images_per_second);
  }
}

bool ImageThrottle::admit(std::uint32_t channel, std::uint64_t receive_ns) {
  if (min_gap_ns_ == 0) return true;
  const auto it = last_ns_.find(channel);
  if (it != last_ns_.end() && receive_ns - it->second < min_gap_ns_) {
    ++held_back_[channel];
    return false;
  }
  last_ns_[channel] = receive_ns;
  return true;
}

}  // namespace oscar::bridge
