#include "framegrabber_kernel.hpp"

#include <opencv2/imgproc.hpp>

#include <oscar/kernel_registry.hpp>

namespace oscar::modules {
namespace {
int scale_divisor(const std::string& mode) {
  return mode == "quarter" ? 4 : mode == "half" ? 2 : 1;
}
bool is_frame_mode(const std::string& mode) {
  return mode == "full" || mode == "half" || mode == "quarter";
}
}  // namespace

void Framegrabber::Params::describe(ParamSpec& spec) {
  spec.field("source", source, "v4l2:/dev/videoN, file:PATH, dir:PATH or synthetic[:moving|static]")
      .fixed();
  spec.field("camera_id", camera_id, "camera name in the cues (default: the kernel's name)")
      .fixed();
  spec.field("frame_mode", frame_mode, "full, half (1/2 per axis) or quarter (1/4 per axis)")
      .one_of({"full", "half", "quarter"});
  spec.field("loop", loop, "file/dir/synthetic: start again at the end").fixed();
  spec.field("width", width, "synthetic image columns (full frame)").range(16, 8192).fixed();
  spec.field("height", height, "synthetic image rows (full frame)").range(16, 8192).fixed();
  spec.field("fx", fx, "focal length x, full frame, px (0 = unknown; synthetic: width)")
      .at_least(0)
      .fixed();
  spec.field("fy", fy, "focal length y, full frame, px (0 = unknown; synthetic: fx)")
      .at_least(0)
      .fixed();
  spec.field("cx", cx, "principal point x, full frame, px (0 = unknown; synthetic: middle)")
      .at_least(0)
      .fixed();
  spec.field("cy", cy, "principal point y, full frame, px (0 = unknown; synthetic: middle)")
      .at_least(0)
      .fixed();
  spec.field("position_m", position_m, "camera centre in the world frame 'x,y,z' (axes parallel)")
      .fixed();
  spec.field("tag_layout", tag_layout, "synthetic: tag36h11 ids on the target 'id:x,y,z;...' (m)")
      .fixed();
  spec.field("tag_size_m", tag_size_m, "synthetic: tag edge (black border), m")
      .range(0.001, 10)
      .fixed();
  spec.field("distance_m", distance_m, "synthetic: mean target distance, m")
      .range(0.05, 100)
      .fixed();
  spec.field("motion_period_s", motion_period_s, "synthetic: period of the target's motion, s")
      .range(0.1, 1e6)
      .fixed();
  spec.field("scene_fps", scene_fps, "synthetic: frame k shows scene time k / scene_fps")
      .range(0.01, 1e4)
      .fixed();
  spec.field("noise_sigma", noise_sigma, "synthetic: Gaussian pixel noise, grey levels")
      .range(0, 128);
  spec.field("blur_sigma_px", blur_sigma_px, "synthetic: Gaussian blur, px").range(0, 20);
  spec.field("seed", seed, "synthetic: noise seed").at_least(0).fixed();
}

Framegrabber::Framegrabber(KernelSetup& setup)
    : image_(setup.output<GvImage>("image")), frame_(setup.output<CameraImage>("frame")) {
  setup.params(params_);
  setup.command<SetFrameMode>("frame_mode",
                              [this](const SetFrameMode& r) { return set_frame_mode(r); });
  frame_mode_ = param_frame_mode_ = params_.frame_mode;
  intrinsics_ = {params_.fx, params_.fy, params_.cx, params_.cy};  // fixed parameters
  name_ = params_.camera_id.empty() ? setup.kernel_name() : params_.camera_id;
  // Validate now (bad YAML is refused at load time); devices and files open on activation.
  source_ = parse_source(params_.source);
  position_ = parse_vector3(params_.position_m, "parameter 'position_m'");
  if (source_.kind == SourceSpec::Kind::kSynthetic) parse_tag_layout(params_.tag_layout);
}

Framegrabber::~Framegrabber() = default;

void Framegrabber::on_activate() { open(); }

void Framegrabber::on_deactivate() {
  camera_.reset();
  scene_.reset();
}

void Framegrabber::open() {
  if (camera_ || scene_) return;
  if (source_.kind != SourceSpec::Kind::kSynthetic) {
    try {
      camera_ = open_frame_source(source_, params_.loop);
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("framegrabber '{}': {}", name_, e.what()));
    }
    return;
  }
  SceneOptions o;
  o.width = params_.width;
  o.height = params_.height;
  o.fx = params_.fx;
  o.fy = params_.fy;
  o.cx = params_.cx;
  o.cy = params_.cy;
  o.tags = parse_tag_layout(params_.tag_layout);
  o.tag_size_m = params_.tag_size_m;
  o.distance_m = params_.distance_m;
  o.moving = source_.path == "moving";
  o.motion_period_s = params_.motion_period_s;
  o.scene_fps = params_.scene_fps;
  o.seed = static_cast<std::uint64_t>(params_.seed);
  o.camera_position_m = position_;
  scene_ = std::make_unique<SyntheticScene>(o);
  // The scene's defaults are the camera's intrinsics. They are the kernel's own: the parameters
  // belong to the frame, which reads them from other threads (oscar ps).
  intrinsics_ = {scene_->options().fx, scene_->options().fy, scene_->options().cx,
                 scene_->options().cy};
}

// The command changes only the kernel's own mode: the parameter values belong to the frame,
// which reads them from other threads (oscar ps).
CommandAnswer Framegrabber::set_frame_mode(const SetFrameMode& request) {
  if (!is_frame_mode(request.mode())) {
    return CommandAnswer::refuse(
        fmt::format("frame mode '{}' is not full, half or quarter", request.mode()));
  }
  auto text = fmt::format("frame mode {} -> {}", frame_mode(), request.mode());
  frame_mode_ = request.mode();
  return CommandAnswer::accept(std::move(text));
}

// A set_param that changes the parameter wins over an earlier command, and the other way round.
const std::string& Framegrabber::frame_mode() {
  if (params_.frame_mode != param_frame_mode_) frame_mode_ = param_frame_mode_ = params_.frame_mode;
  return frame_mode_;
}

void Framegrabber::process(Cycle& cycle) {
  open();
  if (ended_) return;
  GroundTruth truth;
  cv::Mat full;
  if (scene_) {
    scene_->set_degradation(params_.noise_sigma, params_.blur_sigma_px);
    full = scene_->render(frames_, truth);
  } else {
    try {
      full = camera_->next();
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("framegrabber '{}': {}", name_, e.what()));
    }
    if (full.empty()) {
      ended_ = true;  // a regular outcome: the recording is over
      return;
    }
  }
  ++frames_;
  publish(full, std::move(truth), cycle.now());
}

void Framegrabber::publish(const cv::Mat& full, GroundTruth truth, Stamp acquired) {
  const int div = scale_divisor(frame_mode());
  cv::Mat img = full;
  if (div > 1) cv::resize(full, img, {full.cols / div, full.rows / div}, 0, 0, cv::INTER_AREA);
  if (!img.isContinuous()) img = img.clone();
  const double f = static_cast<double>(img.cols) / full.cols;
  if (img.cols > 32767 || img.rows > 32767) {
    throw std::runtime_error(fmt::format("framegrabber '{}': a {}x{} image does not fit a cue",
                                         name_, img.cols, img.rows));
  }
  for (auto& t : truth.tags()) {
    for (auto& c : t.corners()) c *= f;
  }
  CameraImage frame;
  append_stamp(frame.header(), acquired);  // the grab started at the cycle's time
  frame.camera_id(name_);
  frame.encoding("mono8");
  frame.width(static_cast<std::uint16_t>(img.cols));
  frame.height(static_cast<std::uint16_t>(img.rows));
  frame.fx(intrinsics_.fx * f);
  frame.fy(intrinsics_.fy * f);
  frame.cx(intrinsics_.cx * f);
  frame.cy(intrinsics_.cy * f);
  frame.position({position_.x(), position_.y(), position_.z()});
  frame.data().assign(img.data, img.data + img.total());
  frame.truth(std::move(truth));
  GvImage grey;
  grey.header() = frame.header();
  grey.dx(static_cast<std::int16_t>(img.cols));
  grey.dy(static_cast<std::int16_t>(img.rows));
  grey.image() = frame.data();
  image_.publish(std::move(grey));
  frame_.publish(std::move(frame));
}

// Stub: a flat grey frame of the configured size with no tags, so detectors downstream can run.
void Framegrabber::stub(Cycle& cycle) {
  cv::Mat full(params_.height, params_.width, CV_8U, cv::Scalar(128));
  ++frames_;
  publish(full, GroundTruth{}, cycle.now());
}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::Framegrabber, "framegrabber")
