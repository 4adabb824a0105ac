#include "frame_source.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace oscar::modules {
namespace fs = std::filesystem;
namespace {

cv::Mat to_grey(const cv::Mat& frame) {
  if (frame.channels() == 1) return frame;
  cv::Mat grey;
  cv::cvtColor(frame, grey, frame.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

class VideoSource final : public FrameSource {
 public:
  VideoSource(const SourceSpec& spec, bool loop) : path_(spec.path), loop_(loop) {
    const bool device = spec.kind == SourceSpec::Kind::kV4l2;
    if (!fs::exists(path_)) {
      throw std::runtime_error(
          fmt::format("{} '{}' does not exist", device ? "video device" : "video file", path_));
    }
    // One backend each (V4L2 for devices, FFmpeg for files): no probing of the others, whose
    // GStreamer path scans USB devices and leaks in plugins it unloads again.
    const bool opened = capture_.open(path_, device ? cv::CAP_V4L2 : cv::CAP_FFMPEG);
    if (!opened || !capture_.isOpened()) {
      throw std::runtime_error(
          fmt::format("cannot open {} '{}' (OpenCV's {} backend cannot read it)",
                      device ? "video device" : "video file", path_, device ? "V4L2" : "FFmpeg"));
    }
    can_rewind_ = !device;
  }
  cv::Mat next() override {
    cv::Mat frame;
    if (capture_.read(frame) && !frame.empty()) return to_grey(frame);
    if (!can_rewind_)
      throw std::runtime_error(fmt::format("video device '{}' delivered no frame", path_));
    if (!loop_) return {};
    capture_.set(cv::CAP_PROP_POS_FRAMES, 0);
    if (capture_.read(frame) && !frame.empty()) return to_grey(frame);
    throw std::runtime_error(fmt::format("video file '{}' has no readable frame", path_));
  }

 private:
  std::string path_;
  bool loop_;
  bool can_rewind_ = false;
  cv::VideoCapture capture_;
};

class DirSource final : public FrameSource {
 public:
  DirSource(const std::string& dir, bool loop) : loop_(loop) {
    if (!fs::is_directory(dir)) {
      throw std::runtime_error(fmt::format("image directory '{}' does not exist", dir));
    }
    static const std::vector<std::string> kExt = {".png", ".jpg", ".jpeg", ".bmp",
                                                  ".pgm", ".ppm", ".tif",  ".tiff"};
    for (const auto& e : fs::directory_iterator(dir)) {
      auto ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (e.is_regular_file() && std::find(kExt.begin(), kExt.end(), ext) != kExt.end()) {
        files_.push_back(e.path().string());
      }
    }
    if (files_.empty()) {
      throw std::runtime_error(fmt::format(
          "image directory '{}' holds no images (.png .jpg .jpeg .bmp .pgm .ppm .tif .tiff)", dir));
    }
    std::sort(files_.begin(), files_.end());  // frame order = file name order
  }
  cv::Mat next() override {
    if (index_ == files_.size()) {
      if (!loop_) return {};
      index_ = 0;
    }
    const auto& file = files_[index_++];
    cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw std::runtime_error(fmt::format("unreadable image '{}'", file));
    return image;
  }

 private:
  bool loop_;
  std::vector<std::string> files_;
  std::size_t index_ = 0;
};
}  // namespace

SourceSpec parse_source(const std::string& text) {
  const auto colon = text.find(':');
  const std::string head = text.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : text.substr(colon + 1);
  SourceSpec s;
  s.path = rest;
  if (head == "synthetic") {
    s.kind = SourceSpec::Kind::kSynthetic;
    if (s.path.empty()) s.path = "moving";
    if (s.path != "moving" && s.path != "static") {
      throw std::invalid_argument(
          fmt::format("source '{}': the synthetic scene is 'moving' or 'static'", text));
    }
    return s;
  }
  if (head == "v4l2") {
    s.kind = SourceSpec::Kind::kV4l2;
  } else if (head == "file") {
    s.kind = SourceSpec::Kind::kFile;
  } else if (head == "dir") {
    s.kind = SourceSpec::Kind::kDir;
  } else {
    throw std::invalid_argument(fmt::format(
        "source '{}': expected v4l2:/dev/videoN, file:PATH, dir:PATH or synthetic[:moving|static]",
        text));
  }
  if (s.path.empty()) throw std::invalid_argument(fmt::format("source '{}' names no path", text));
  return s;
}

std::unique_ptr<FrameSource> open_frame_source(const SourceSpec& spec, bool loop) {
  if (spec.kind == SourceSpec::Kind::kDir) return std::make_unique<DirSource>(spec.path, loop);
  return std::make_unique<VideoSource>(spec, loop);
}

}  // namespace oscar::modules
