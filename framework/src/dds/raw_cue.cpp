#include "oscar/raw_cue.hpp"

#include <stdexcept>

#include "oscar/cue_type_info.hpp"

namespace oscar {

const CueTypeInfo& raw_cue_type() {
  static const CueTypeInfo info{
      .name = "oscar::RawCue",
      .new_topic_type = []() -> eprosima::fastdds::dds::TopicDataType* {
        // A raw input's topic type is the producer's (RawCdrType under its name), never this.
        throw std::logic_error("oscar::RawCue has no DDS type of its own");
      },
      .header = cue_header_access<RawCue>(),
      .make = []() -> std::shared_ptr<void> { return std::make_shared<RawCue>(); },
      .serialize = [](const void* cue) { return static_cast<const RawCue*>(cue)->cdr; },
      .deserialize = [](const std::vector<std::uint8_t>&) -> std::shared_ptr<void> {
        throw std::logic_error("oscar::RawCue cannot be read without the producer's type name");
      },
  };
  return info;
}

std::shared_ptr<const RawCue> to_raw_cue(const CueTypeInfo& type, const void* cue) {
  auto raw = std::make_shared<RawCue>();
  raw->type = type.name;
  raw->cdr = type.serialize(cue);
  raw->cue_header = type.header.read(cue);
  return raw;
}

}  // namespace oscar
