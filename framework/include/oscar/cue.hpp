#pragma once
/// @file What makes a type a cue, and the run-time description the framework keeps of each.

#include <concepts>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <oscar/cue_header.h>

namespace eprosima::fastdds::dds {
class TopicDataType;
}

namespace oscar {

/// A cue type is an IDL struct whose first member is `CueHeader header` (docs/architecture.md,
/// "Topics and QoS classes").
template <class T>
concept CueType = requires(T cue, const T ccue) {
  { cue.header() } -> std::same_as<CueHeader&>;
  { ccue.header() } -> std::same_as<const CueHeader&>;
};

/// Compile-time facts about a cue type; specialised by OSCAR_DECLARE_CUE_TYPE.
template <class T>
struct CueTraits;
/// Compile-time facts about any IDL struct (oscar/idl_type_info.hpp).
template <class T>
struct IdlTraits;

/// What the framework needs to move a cue type it does not know at compile time.
struct CueTypeInfo {
  std::string name;  ///< the DDS type name, e.g. "oscar::GvImage"
  eprosima::fastdds::dds::TopicDataType* (*new_topic_type)();
  const CueHeader& (*header)(const void* cue);
  std::shared_ptr<void> (*make)();
  std::vector<std::uint8_t> (*serialize)(const void* cue);
  /// @throws std::runtime_error if the bytes are not a valid CDR encoding of the type.
  std::shared_ptr<void> (*deserialize)(const std::vector<std::uint8_t>& bytes);
};

/// Registers (or finds) the description of a type by name; used by cue_type_info<T>().
const CueTypeInfo& register_cue_type(CueTypeInfo info);
/// The description of a registered type, or nullptr.
const CueTypeInfo* find_cue_type(const std::string& name);
/// Names of all registered types, sorted.
std::vector<std::string> cue_type_names();

/// The first stamp of a header (its generation time), or 0 if it has none.
inline std::int64_t generation_stamp(const CueHeader& h) {
  return h.stamps().empty() ? 0 : static_cast<std::int64_t>(h.stamps().front());
}

/// Appends a stamp to a header: what a fusing module does with the cues it combines.
inline void append_stamp(CueHeader& h, std::int64_t stamp) {
  h.stamps().push_back(static_cast<unsigned long long>(stamp));
}

}  // namespace oscar

/// Declares the IDL type NS::NAME (generated with its NS::NAME##PubSubType) a cue type (and an
/// IDL struct, so a command port may take it too).
#define OSCAR_DECLARE_CUE_TYPE(NS, NAME)     \
  template <>                                \
  struct oscar::CueTraits<NS::NAME> {        \
    using PubSubType = NS::NAME##PubSubType; \
  };                                         \
  template <>                                \
  struct oscar::IdlTraits<NS::NAME> {        \
    using PubSubType = NS::NAME##PubSubType; \
  };
