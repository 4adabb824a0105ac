#pragma once
/// @file cue_type_info<T>(): the run-time description of a declared cue type.

#include <new>
#include <type_traits>
#include <utility>

#include "oscar/cue.hpp"
#include "oscar/idl_type_info.hpp"

namespace oscar {

/// How the framework reaches the header of a T, whichever form T's header has.
template <CueType T>
CueHeaderAccess cue_header_access() {
  using Form = CueHeaderForm<std::remove_cvref_t<decltype(std::declval<T&>().header())>>;
  return CueHeaderAccess{
      .layout = Form::kLayout,
      .generation_stamp = [](const void* cue) -> std::int64_t {
        return Form::generation_stamp(static_cast<const T*>(cue)->header());
      },
      .read = [](const void* cue) -> CueHeader {
        return Form::read(static_cast<const T*>(cue)->header());
      },
      .complete = [](void* cue, std::uint64_t seq, const std::string& source,
                     const std::function<std::int64_t()>& clock) -> std::int64_t {
        return Form::complete(static_cast<T*>(cue)->header(), seq, source, clock);
      },
      .max_source_length = Form::kMaxSourceLength,
  };
}

/// How a T lies in memory.
template <CueType T>
CueMemory cue_memory() {
  return CueMemory{
      .plain = typename CueTraits<T>::PubSubType().is_plain(),
      .size = sizeof(T),
      .alignment = alignof(T),
      .construct_at = [](void* where) { new (where) T(); },
      .copy_to = [](const void* cue, void* where) { new (where) T(*static_cast<const T*>(cue)); },
  };
}

/// The registered description of T (registered on first use).
template <CueType T>
const CueTypeInfo& cue_type_info() {
  static const CueTypeInfo& info = register_cue_type(CueTypeInfo{
      .name = typename CueTraits<T>::PubSubType().getName(),
      .new_topic_type = []() -> eprosima::fastdds::dds::TopicDataType* {
        return new typename CueTraits<T>::PubSubType();
      },
      .header = cue_header_access<T>(),
      .make = []() -> std::shared_ptr<void> { return std::make_shared<T>(); },
      .serialize = &internal::serialize_idl<T>,
      .deserialize = &internal::deserialize_idl<T>,
      .memory = cue_memory<T>(),
  });
  return info;
}

}  // namespace oscar
