#pragma once
// ImageThrottle: at most so many images per second of each channel to one client. Images are
// most of a bridge's bytes; a viewer rarely needs a camera's full rate, and a browser over a
// thin link would otherwise spend its queue on them. Other channels pass untouched.

#include <cstdint>
#include <map>
#include <string>

namespace oscar::bridge {

/// True for the channels that carry images: OSCAR's image cues and Foxglove's image schemas.
bool is_image_schema(const std::string& schema_name);

class ImageThrottle {
 public:
  /// `images_per_second` <= 0: no limit.
  explicit ImageThrottle(double images_per_second);

  /// Whether an image of `channel` received at `receive_ns` goes out; one that comes sooner
  /// than a period (less a tenth, for jitter) after the last one let through is held back and
  /// counted.
  bool admit(std::uint32_t channel, std::uint64_t receive_ns);
  /// `channel`'s subscription ended: its next image goes out at once.
  void forget(std::uint32_t channel) { last_ns_.erase(channel); }

  bool limits() const { return min_gap_ns_ > 0; }
  /// Images held back so far, by channel (channels with none are absent).
  const std::map<std::uint32_t, std::uint64_t>& held_back() const { return held_back_; }

 private:
  std::uint64_t min_gap_ns_ = 0;
  std::map<std::uint32_t, std::uint64_t> last_ns_;
  std::map<std::uint32_t, std::uint64_t> held_back_;
};

}  // namespace oscar::bridge
