#include "foxglove_messages.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

#include "jpeg_encoder.hpp"

namespace oscar::bridge {
using json = nlohmann::ordered_json;

namespace {
constexpr const char* kWorldFrame = "world";

// foxglove time: {sec, nsec} from a cue's generation stamp (ns since the epoch).
json time_of(const CueHeader& header) {
  const std::uint64_t ns = header.stamps().empty() ? 0 : header.stamps().front();
  return {{"sec", ns / 1'000'000'000u}, {"nsec", ns % 1'000'000'000u}};
}

json vector3(double x, double y, double z) { return {{"x", x}, {"y", y}, {"z", z}}; }
json colour(double r, double g, double b, double a = 1.0) {
  return {{"r", r}, {"g", g}, {"b", b}, {"a", a}};
}
// A pose at (x, y, z) turned by `yaw` (rad, counterclockwise about +z).
json yawed_pose(double x, double y, double z, double yaw) {
  return {{"position", vector3(x, y, z)},
          {"orientation",
           {{"x", 0.0}, {"y", 0.0}, {"z", std::sin(yaw / 2)}, {"w", std::cos(yaw / 2)}}}};
}

bool fills(long width, long height, std::span<const std::uint8_t> pixels) {
  return width > 0 && height > 0 && pixels.size() == static_cast<std::size_t>(width * height);
}

std::optional<std::string> mono8(const CueHeader& header, std::string frame_id, long width,
                                 long height, const std::string& encoding,
                                 std::span<const std::uint8_t> pixels) {
  if (!fills(width, height, pixels)) return std::nullopt;
  return json{{"timestamp", time_of(header)},
              {"frame_id", std::move(frame_id)},
              {"width", width},
              {"height", height},
              {"encoding", encoding},
              {"step", width},
              {"data", base64(pixels)}}
      .dump();
}

std::optional<std::string> jpeg(const CueHeader& header, std::string frame_id, long width,
                                long height, std::span<const std::uint8_t> pixels, int quality) {
  if (!fills(width, height, pixels)) return std::nullopt;
  return json{{"timestamp", time_of(header)},
              {"frame_id", std::move(frame_id)},
              {"format", "jpeg"},
              {"data", base64(encode_mono8_jpeg(pixels, width, height, quality))}}
      .dump();
}

// The producing kernel of a cue: its header's source up to '/'.
std::string kernel_of(const CueHeader& header) {
  const auto& source = header.source();
  return source.substr(0, source.find('/'));
}

// A plain image's pixels: its first byte_count bytes; nullopt if byte_count exceeds its array.
std::optional<std::span<const std::uint8_t>> pixels_of(const PlainGvImage& image) {
  if (image.byte_count() > image.image().size()) return std::nullopt;
  return std::span<const std::uint8_t>(image.image()).first(image.byte_count());
}
}  // namespace

std::string base64(std::span<const std::uint8_t> bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
    for (int shift = 18; shift >= 0; shift -= 6) out += kAlphabet[(v >> shift) & 0x3f];
  }
  if (const auto rest = bytes.size() - i; rest > 0) {
    const std::uint32_t v = (bytes[i] << 16) | (rest == 2 ? bytes[i + 1] << 8 : 0);
    out += kAlphabet[(v >> 18) & 0x3f];
    out += kAlphabet[(v >> 12) & 0x3f];
    out += rest == 2 ? kAlphabet[(v >> 6) & 0x3f] : '=';
    out += '=';
  }
  return out;
}

std::optional<std::string> raw_image_json(const GvImage& image) {
  return mono8(image.header(), kernel_of(image.header()), image.dx(), image.dy(), "mono8",
               image.image());
}

std::optional<std::string> compressed_image_json(const GvImage& image, int quality) {
  return jpeg(image.header(), kernel_of(image.header()), image.dx(), image.dy(), image.image(),
              quality);
}

std::optional<std::string> raw_image_json(const PlainGvImage& image) {
  const auto pixels = pixels_of(image);
  if (!pixels) return std::nullopt;
  const auto header = CueHeaderForm<PlainCueHeader>::read(image.header());
  return mono8(header, kernel_of(header), image.dx(), image.dy(), "mono8", *pixels);
}

std::optional<std::string> compressed_image_json(const PlainGvImage& image, int quality) {
  const auto pixels = pixels_of(image);
  if (!pixels) return std::nullopt;
  const auto header = CueHeaderForm<PlainCueHeader>::read(image.header());
  return jpeg(header, kernel_of(header), image.dx(), image.dy(), *pixels, quality);
}

std::optional<std::string> compressed_image_json(const CameraImage& image, int quality) {
  if (image.encoding() != "mono8") return std::nullopt;
  return jpeg(image.header(), image.camera_id(), image.width(), image.height(), image.data(),
              quality);
}

std::optional<std::string> raw_image_json(const CameraImage& image) {
  if (image.encoding() != "mono8") return std::nullopt;  // the only one OSCAR's cameras make
  return mono8(image.header(), image.camera_id(), image.width(), image.height(), image.encoding(),
               image.data());
}

std::optional<std::string> pose_in_frame_json(const LandmarkPose& pose) {
  if (!pose.valid()) return std::nullopt;
  const auto& t = pose.pose().t();
  const auto& q = pose.pose().q();  // w, x, y, z
  return json{{"timestamp", time_of(pose.header())},
              {"frame_id", kWorldFrame},
              {"pose",
               {{"position", vector3(t[0], t[1], t[2])},
                {"orientation", {{"x", q[1]}, {"y", q[2]}, {"z", q[3]}, {"w", q[0]}}}}}}
      .dump();
}

std::optional<std::string> scene_update_json(const RobotState& state) {
  constexpr double kDiscHeight_m = 0.2;
  const double r = state.radius();
  const bool working = !state.job().id().empty();
  const json body = state.broken() ? colour(0.9, 0.2, 0.2)
                    : working      ? colour(0.2, 0.75, 0.3)
                                   : colour(0.25, 0.45, 0.9);
  const json disc = {{"pose", yawed_pose(state.x(), state.y(), kDiscHeight_m / 2, state.heading())},
                     {"size", vector3(2 * r, 2 * r, kDiscHeight_m)},
                     {"bottom_scale", 1.0},
                     {"top_scale", 1.0},
                     {"color", body}};
  const json heading = {{"pose", yawed_pose(state.x(), state.y(), kDiscHeight_m, state.heading())},
                        {"shaft_length", r},
                        {"shaft_diameter", r / 6},
                        {"head_length", r / 2},
                        {"head_diameter", r / 2.5},
                        {"color", colour(1, 1, 1)}};
  const json name = {{"pose", yawed_pose(state.x(), state.y(), 2 * kDiscHeight_m + r, 0)},
                     {"billboard", true},
                     {"font_size", 14.0},
                     {"scale_invariant", true},
                     {"color", colour(1, 1, 1)},
                     {"text", state.robot()}};
  json metadata = json::array();
  metadata.push_back({{"key", "speed_mps"}, {"value", std::to_string(state.speed())}});
  metadata.push_back({{"key", "job"}, {"value", state.job().id()}});
  if (state.broken()) metadata.push_back({{"key", "fault"}, {"value", state.fault()}});
  const json entity = {{"timestamp", time_of(state.header())},
                       {"frame_id", kWorldFrame},
                       {"id", state.robot()},
                       {"lifetime", {{"sec", 0}, {"nsec", 0}}},  // until replaced
                       {"frame_locked", false},
                       {"metadata", metadata},
                       {"arrows", json::array({heading})},
                       {"cubes", json::array()},
                       {"spheres", json::array()},
                       {"cylinders", json::array({disc})},
                       {"lines", json::array()},
                       {"triangles", json::array()},
                       {"texts", json::array({name})},
                       {"models", json::array()}};
  return json{{"deletions", json::array()}, {"entities", json::array({entity})}}.dump();
}

}  // namespace oscar::bridge
