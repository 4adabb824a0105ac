#pragma once
// OSCAR cues as Foxglove's published message schemas, JSON encoded (docs/foxglove.md, "Side
// channels"): what Foxglove's Image and 3D panels draw without knowing OSCAR's types. Each
// function is a pure function of one cue; nullopt means there is nothing to draw.

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include <oscar/cue_types.hpp>
#include <oscar/perception_types.hpp>
#include <oscar/plain_cue_types.hpp>
#include <oscar/swarm_types.hpp>

namespace oscar::bridge {

/// RFC 4648 base64 with padding: how JSON carries bytes (schema contentEncoding "base64").
std::string base64(std::span<const std::uint8_t> bytes);

/// A foxglove.RawImage (mono8, step = width) of a grey-value image; frame_id is the producing
/// kernel (the header's source up to '/'). nullopt if the pixels do not fill dx x dy.
std::optional<std::string> raw_image_json(const GvImage& image);
/// The same of a camera image (frame_id: its camera_id; encoding as it says, mono8).
std::optional<std::string> raw_image_json(const CameraImage& image);
/// The same of a plain grey-value image (its first byte_count bytes of pixels); nullopt also if
/// byte_count is more than the image holds.
std::optional<std::string> raw_image_json(const PlainGvImage& image);

/// A foxglove.CompressedImage (format "jpeg", greyscale) of a grey-value image at JPEG
/// `quality` (1..100); frame_id as its RawImage. nullopt if the pixels do not fill dx x dy.
/// @throws std::runtime_error if this build has no JPEG encoder (jpeg_available()).
std::optional<std::string> compressed_image_json(const GvImage& image, int quality);
/// The same of a mono8 camera image (frame_id: its camera_id).
std::optional<std::string> compressed_image_json(const CameraImage& image, int quality);
/// The same of a plain grey-value image.
std::optional<std::string> compressed_image_json(const PlainGvImage& image, int quality);

/// A foxglove.PoseInFrame of the fused target pose, frame "world"; nullopt if it is not valid.
std::optional<std::string> pose_in_frame_json(const LandmarkPose& pose);

/// A foxglove.SceneUpdate with the robot as one entity (id: the robot's name, frame "world"):
/// a disc of its radius (green while it works a job, blue when idle, red when broken), an arrow
/// along its heading and its name; metadata: speed, job, fault.
std::optional<std::string> scene_update_json(const RobotState& state);

}  // namespace oscar::bridge
