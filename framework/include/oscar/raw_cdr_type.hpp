#pragma once
// A Fast DDS type support that keeps each sample's serialized payload (encapsulation header
// and CDR) as bytes, registered under any type name: the recorder subscribes to topics without
// knowing their types, and the replayer publishes the recorded bytes unchanged.

#include <cstdint>
#include <string>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>

namespace oscar {

/// One sample: the payload exactly as it was on the wire.
struct RawSample {
  std::vector<std::uint8_t> bytes;
};

class RawCdrType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  explicit RawCdrType(const std::string& type_name);
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override;
  void* createData() override;
  void deleteData(void* data) override;
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle,
              bool force_md5) override;
};

}  // namespace oscar
