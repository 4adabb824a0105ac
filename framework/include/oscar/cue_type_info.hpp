#pragma once
/// @file cue_type_info<T>(): the run-time description of a declared cue type.

#include "oscar/cue.hpp"
#include "oscar/idl_type_info.hpp"

namespace oscar {

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
      .serialize = &internal::serialize_idl<T>,
      .deserialize = &internal::deserialize_idl<T>,
  });
  return info;
}

}  // namespace oscar
