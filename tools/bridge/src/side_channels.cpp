#include "side_channels.hpp"

#include <stdexcept>

#include "foxglove_messages.hpp"
#include "json_schemas.hpp"
#include "oscar/idl_type_info.hpp"
#include "oscar/topics.hpp"

namespace oscar::bridge {
namespace {

struct Kind {
  const char* source_type;
  const char* schema_name;
};
// One line per drawable type: the only place that says which cue becomes which schema.
constexpr Kind kKinds[] = {
    {"oscar::GvImage", "foxglove.RawImage"},         {"oscar::CameraImage", "foxglove.RawImage"},
    {"oscar::LandmarkPose", "foxglove.PoseInFrame"}, {"oscar::RobotState", "foxglove.SceneUpdate"},
    {"oscar::SystemState", "oscar.SystemGraph"},
};

template <IdlStruct T>
T decode(const std::vector<std::uint8_t>& cdr) {
  return *std::static_pointer_cast<T>(internal::deserialize_idl<T>(cdr));
}

}  // namespace

std::optional<ChannelInfo> side_channel_for(const std::string& topic, const std::string& type) {
  for (const auto& k : kKinds) {
    if (type != k.source_type) continue;
    std::string side;
    if (k.schema_name == kSystemGraphSchema) {
      if (topic != topics::system_state().name) return std::nullopt;
      side = "foxglove/system/graph";
    } else if (topics::is_cue(topic)) {
      side = "foxglove/" + topic.substr(topics::kCuePrefix.size());
    } else {
      return std::nullopt;
    }
    return ChannelInfo{.id = 0,
                       .topic = side,
                       .schema_name = k.schema_name,
                       .schema = json_schema(k.schema_name),
                       .encoding = "json",
                       .schema_encoding = "jsonschema",
                       .source = topic};
  }
  return std::nullopt;
}

std::optional<std::string> convert_sample(const std::string& source_type,
                                          const std::vector<std::uint8_t>& cdr) {
  if (source_type == "oscar::GvImage") return raw_image_json(decode<GvImage>(cdr));
  if (source_type == "oscar::CameraImage") return raw_image_json(decode<CameraImage>(cdr));
  if (source_type == "oscar::LandmarkPose") return pose_in_frame_json(decode<LandmarkPose>(cdr));
  if (source_type == "oscar::RobotState") return scene_update_json(decode<RobotState>(cdr));
  throw std::runtime_error("the bridge converts no sample of " + source_type);
}

}  // namespace oscar::bridge
