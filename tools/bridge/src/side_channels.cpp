#include "side_channels.hpp"

#include <stdexcept>

#include "foxglove_messages.hpp"
#include "jpeg_encoder.hpp"
#include "json_schemas.hpp"
#include "oscar/idl_type_info.hpp"
#include "oscar/topics.hpp"

namespace oscar::bridge {
namespace {

struct Kind {
  const char* source_type;
  const char* schema_name;
  const char* suffix;  // after the side channel's topic foxglove/K/C
};
// One line per side channel: the only place that says which cue becomes which schema.
constexpr Kind kKinds[] = {
    {"oscar::GvImage", "foxglove.RawImage", ""},
    {"oscar::GvImage", "foxglove.CompressedImage", "/compressed"},
    {"oscar::PlainGvImage", "foxglove.RawImage", ""},
    {"oscar::PlainGvImage", "foxglove.CompressedImage", "/compressed"},
    {"oscar::CameraImage", "foxglove.RawImage", ""},
    {"oscar::CameraImage", "foxglove.CompressedImage", "/compressed"},
    {"oscar::LandmarkPose", "foxglove.PoseInFrame", ""},
    {"oscar::RobotState", "foxglove.SceneUpdate", ""},
    {"oscar::SystemState", "oscar.SystemGraph", ""},
};

// On the heap: a PlainGvImage is 442 KB.
template <IdlStruct T>
std::shared_ptr<const T> decode(const std::vector<std::uint8_t>& cdr) {
  return std::static_pointer_cast<const T>(internal::deserialize_idl<T>(cdr));
}

template <class Image>
std::optional<std::string> image_json(const std::vector<std::uint8_t>& cdr, bool jpeg,
                                      const ConversionSettings& settings) {
  const auto image = decode<Image>(cdr);
  return jpeg ? compressed_image_json(*image, settings.jpeg_quality) : raw_image_json(*image);
}

}  // namespace

std::vector<ChannelInfo> side_channels_for(const std::string& topic, const std::string& type) {
  std::vector<ChannelInfo> out;
  for (const auto& k : kKinds) {
    if (type != k.source_type) continue;
    if (k.schema_name == kCompressedImageSchema && !jpeg_available()) continue;
    std::string side;
    if (k.schema_name == kSystemGraphSchema) {
      if (topic != topics::system_state().name) continue;
      side = "foxglove/system/graph";
    } else if (topics::is_cue(topic)) {
      side = "foxglove/" + topic.substr(topics::kCuePrefix.size()) + k.suffix;
    } else {
      continue;
    }
    out.push_back(ChannelInfo{.id = 0,
                              .topic = side,
                              .schema_name = k.schema_name,
                              .schema = json_schema(k.schema_name),
                              .encoding = "json",
                              .schema_encoding = "jsonschema",
                              .source = topic});
  }
  return out;
}

std::optional<std::string> convert_sample(const std::string& source_type,
                                          const std::string& schema_name,
                                          const std::vector<std::uint8_t>& cdr,
                                          const ConversionSettings& settings) {
  bool offered = false;
  for (const auto& k : kKinds) {
    offered = offered || (source_type == k.source_type && schema_name == k.schema_name);
  }
  if (!offered || schema_name == kSystemGraphSchema) {
    throw std::runtime_error("the bridge converts no sample of " + source_type + " to " +
                             schema_name);
  }
  const bool jpeg = schema_name == kCompressedImageSchema;
  if (source_type == "oscar::GvImage") return image_json<GvImage>(cdr, jpeg, settings);
  if (source_type == "oscar::PlainGvImage") return image_json<PlainGvImage>(cdr, jpeg, settings);
  if (source_type == "oscar::CameraImage") return image_json<CameraImage>(cdr, jpeg, settings);
  if (source_type == "oscar::LandmarkPose") return pose_in_frame_json(*decode<LandmarkPose>(cdr));
  return scene_update_json(*decode<RobotState>(cdr));  // the last kind kKinds offers
}

}  // namespace oscar::bridge
