#pragma once
/// @file cue_type_info<T>(): the run-time description of a declared cue type.

#include <stdexcept>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "oscar/cue.hpp"

namespace oscar {

namespace internal {
template <CueType T>
std::vector<std::uint8_t> serialize_cue(const void* cue) {
  typename CueTraits<T>::PubSubType type;
  void* data = const_cast<void*>(cue);  // the Fast DDS 2.9 API is not const-correct
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
  if (!type.serialize(data, &payload))
    throw std::runtime_error(std::string("cannot serialize ") + type.getName());
  return {payload.data, payload.data + payload.length};
}

template <CueType T>
std::shared_ptr<void> deserialize_cue(const std::vector<std::uint8_t>& bytes) {
  typename CueTraits<T>::PubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(bytes.size());
  auto cue = std::make_shared<T>();
  bool ok = false;
  try {
    ok = type.deserialize(&payload, cue.get());
  } catch (const std::exception&) {
    ok = false;
  }
  if (!ok) {
    throw std::runtime_error("malformed " + std::string(type.getName()) + ": " +
                             std::to_string(bytes.size()) + " bytes are no valid CDR encoding");
  }
  return cue;
}
}  // namespace internal

/// The registered description of T (registered on first use).
template <CueType T>
const CueTypeInfo& cue_type_info() {
  static const CueTypeInfo& info = register_cue_type(CueTypeInfo{
      .name = typename CueTraits<T>::PubSubType().getName(),
      .new_topic_type = []() -> eprosima::fastdds::dds::TopicDataType* {
        return new typename CueTraits<T>::PubSubType();
      },
      .header = [](const void* cue) -> const CueHeader& {
        return static_cast<const T*>(cue)->header();
      },
      .make = []() -> std::shared_ptr<void> { return std::make_shared<T>(); },
      .serialize = &internal::serialize_cue<T>,
      .deserialize = &internal::deserialize_cue<T>,
  });
  return info;
}

}  // namespace oscar
