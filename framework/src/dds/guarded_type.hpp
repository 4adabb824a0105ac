#pragma once
// The type support DdsParticipant::topic() registers for every type: it delegates to the
// generated one (or RawCdrType) and turns a sample that cannot be decoded into a refusal, which
// Fast DDS 2.9 answers by dropping the sample. Without it an exception from Fast CDR (a boolean
// byte other than 0 or 1, a sample that ends early) escaped on a Fast DDS thread and aborted the
// process: Fast DDS's reader calls the type's deserialize() directly, not TypeSupport's, which
// would have caught it.

#include <memory>

#include <fastdds/dds/topic/TopicDataType.hpp>

#include "dds/wire_bounds.hpp"

namespace oscar::internal {

class GuardedType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  /// Takes ownership of `inner`; `check` (nullable) runs on a sample's bytes before `inner`
  /// decodes them.
  GuardedType(eprosima::fastdds::dds::TopicDataType* inner, WireCheck check);

  /// The type support it delegates to.
  const eprosima::fastdds::dds::TopicDataType& inner() const { return *inner_; }

  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  /// False, after noting why (internal::note_malformed_sample), if the bytes fail the check or
  /// the inner type throws decoding them.
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override;
  void* createData() override;
  void deleteData(void* data) override;
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle,
              bool force_md5) override;
  bool is_bounded() const override;
  bool is_plain() const override;
  bool construct_sample(void* memory) const override;

 private:
  std::unique_ptr<eprosima::fastdds::dds::TopicDataType> inner_;
  WireCheck check_;
};

}  // namespace oscar::internal
