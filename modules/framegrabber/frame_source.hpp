#pragma once

#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace oscar::modules {

/// The framegrabber's `source` parameter, parsed.
struct SourceSpec {
  enum class Kind { kV4l2, kFile, kDir, kSynthetic };
  Kind kind = Kind::kSynthetic;
  std::string path;  ///< device, video file or directory; for synthetic the scene ("moving")
};

/// Parses `v4l2:/dev/videoN`, `file:PATH`, `dir:PATH`, `synthetic[:moving|static]`.
/// @throws std::invalid_argument naming the forms.
SourceSpec parse_source(const std::string& text);

/// Where real frames come from: a V4L2 device, a video file or a directory of images.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame as 8-bit grey, or an empty matrix when a non-looping source has ended.
  /// @throws std::runtime_error if a frame cannot be read (unreadable image, device gone).
  virtual cv::Mat next() = 0;
};

/// Opens a v4l2, file or dir source.
/// @throws std::runtime_error naming the path if it is missing, empty or cannot be opened.
std::unique_ptr<FrameSource> open_frame_source(const SourceSpec& spec, bool loop);

}  // namespace oscar::modules
