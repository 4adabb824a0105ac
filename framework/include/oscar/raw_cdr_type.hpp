#pragma once
/// @file A Fast DDS type support that keeps each sample's serialized payload (encapsulation
/// header and CDR) as bytes, registered under any type name: what subscribes to topics without
/// knowing their types (oscar record, the frame for raw inputs) and what publishes recorded
/// bytes unchanged (oscar replay). Its samples are RawCue.

#include <cstdint>
#include <string>

#include <fastdds/dds/topic/TopicDataType.hpp>

#include "oscar/raw_cue.hpp"

namespace oscar {

class RawCdrType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  explicit RawCdrType(const std::string& type_name);
  /// Writes RawCue::cdr as it is.
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  /// Fills a RawCue: this type's name, the payload and the header read from it (laid out as
  /// the type's name says: cue_header_layout()).
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override;
  void* createData() override;
  void deleteData(void* data) override;
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle,
              bool force_md5) override;

 private:
  CueHeaderLayout layout_ = CueHeaderLayout::kSequences;
};

}  // namespace oscar
