#pragma once
/// @file idl_type_info<T>(): the run-time description of any OSCAR IDL struct (a command's
/// request, a cue), and its CDR encoding as the wire carries it.

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fastdds/rtps/common/SerializedPayload.h>

namespace oscar {

/// Compile-time facts about an IDL struct: its generated PubSubType. Specialised by
/// OSCAR_DECLARE_IDL_TYPE, and by OSCAR_DECLARE_CUE_TYPE for every cue type.
template <class T>
struct IdlTraits;

/// An IDL struct declared with OSCAR_DECLARE_IDL_TYPE (or OSCAR_DECLARE_CUE_TYPE): what a
/// command port may take as its request type. Unlike a cue type it needs no CueHeader.
template <class T>
concept IdlStruct = requires {
  typename IdlTraits<T>::PubSubType;
};

/// What the framework needs to move an IDL type it does not know at compile time.
struct IdlTypeInfo {
  std::string name;  ///< the DDS type name, e.g. "oscar::SetFrameMode"
  std::shared_ptr<void> (*make)();
  std::vector<std::uint8_t> (*serialize)(const void* value);
  /// @throws std::runtime_error if the bytes are not a valid CDR encoding of the type.
  std::shared_ptr<void> (*deserialize)(const std::vector<std::uint8_t>& bytes);
};

namespace internal {
/// The CDR encoding (with its 4-byte encapsulation header) of `value`, a T.
template <IdlStruct T>
std::vector<std::uint8_t> serialize_idl(const void* value) {
  typename IdlTraits<T>::PubSubType type;
  void* data = const_cast<void*>(value);  // the Fast DDS 2.9 API is not const-correct
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
  if (!type.serialize(data, &payload))
    throw std::runtime_error(std::string("cannot serialize ") + type.getName());
  return {payload.data, payload.data + payload.length};
}

/// A T decoded from its CDR encoding.
/// @throws std::runtime_error "malformed <type>: N bytes are no valid CDR encoding".
template <IdlStruct T>
std::shared_ptr<void> deserialize_idl(const std::vector<std::uint8_t>& bytes) {
  typename IdlTraits<T>::PubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(bytes.size());
  auto value = std::make_shared<T>();
  bool ok = false;
  try {
    ok = bytes.size() >= 4 && type.deserialize(&payload, value.get());
  } catch (const std::exception&) {
    ok = false;
  }
  if (!ok) {
    throw std::runtime_error("malformed " + std::string(type.getName()) + ": " +
                             std::to_string(bytes.size()) + " bytes are no valid CDR encoding");
  }
  return value;
}
}  // namespace internal

/// The description of T.
template <IdlStruct T>
const IdlTypeInfo& idl_type_info() {
  static const IdlTypeInfo info{
      .name = typename IdlTraits<T>::PubSubType().getName(),
      .make = []() -> std::shared_ptr<void> { return std::make_shared<T>(); },
      .serialize = &internal::serialize_idl<T>,
      .deserialize = &internal::deserialize_idl<T>,
  };
  return info;
}

}  // namespace oscar

/// Declares the IDL struct NS::NAME (generated with its NS::NAME##PubSubType) an IdlStruct:
/// what a command port's request type needs (docs/kernels.md, "Command ports").
#define OSCAR_DECLARE_IDL_TYPE(NS, NAME)     \
  template <>                                \
  struct oscar::IdlTraits<NS::NAME> {        \
    using PubSubType = NS::NAME##PubSubType; \
  };
