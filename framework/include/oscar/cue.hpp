#pragma once
/// @file What makes a type a cue, and the run-time description the framework keeps of each.

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <oscar/cue_header.h>

namespace eprosima::fastdds::dds {
class TopicDataType;
}

namespace oscar {

/// The fixed-size header of the plain cue types (oscar/plain_cues.idl; declared with its cue
/// types in oscar/plain_cue_types.hpp): the CueHeader's meaning, bounded.
class PlainCueHeader;

/// A reference to one of the two headers a cue may start with.
template <class R>
concept CueHeaderRef = std::same_as<R, CueHeader&> || std::same_as<R, PlainCueHeader&>;
template <class R>
concept ConstCueHeaderRef =
    std::same_as<R, const CueHeader&> || std::same_as<R, const PlainCueHeader&>;

/// A cue type is an IDL struct whose first member is its header: `CueHeader header`
/// (docs/architecture.md, "Topics and QoS classes"), or `PlainCueHeader header` for the plain
/// types (docs/zero_copy.md).
template <class T>
concept CueType = requires(T cue, const T ccue) {
  { cue.header() } -> CueHeaderRef;
  { ccue.header() } -> ConstCueHeaderRef;
};

/// Compile-time facts about a cue type; specialised by OSCAR_DECLARE_CUE_TYPE.
template <class T>
struct CueTraits;
/// Compile-time facts about any IDL struct (oscar/idl_type_info.hpp).
template <class T>
struct IdlTraits;

/// How a header lies in CDR: CueHeader's length-prefixed stamps and source, or PlainCueHeader's
/// fixed arrays (8 stamps, a count, 64 characters).
enum class CueHeaderLayout : std::uint8_t { kSequences, kFixed };

/// What the framework does with a cue's header without knowing the cue's type or its header's
/// form: read the generation stamp, complete the header on publish, read it for tools.
struct CueHeaderAccess {
  CueHeaderLayout layout = CueHeaderLayout::kSequences;
  /// The first stamp (generation time), 0 if there is none.
  std::int64_t (*generation_stamp)(const void* cue) = nullptr;
  /// The stamps, source and seq as a CueHeader value (a copy): what raw inputs and tools read.
  CueHeader (*read)(const void* cue) = nullptr;
  /// On publish: sets seq and source, then reads `clock` for the generation stamp if there is
  /// none: last, so that the stamp says when the cue was complete. Returns the generation stamp
  /// (the clock's, or the one the kernel set), so that the output need not read it back. The
  /// source must fit (max_source_length; outputs check it when they are declared).
  std::int64_t (*complete)(void* cue, std::uint64_t seq, const std::string& source,
                           const std::function<std::int64_t()>& clock) = nullptr;
  /// The longest source ("<kernel>/<channel>") the header holds.
  std::size_t max_source_length = std::numeric_limits<std::size_t>::max();
};

/// How the framework reads and completes a header of type H; specialised below for CueHeader
/// and in oscar/plain_cue_types.hpp for PlainCueHeader.
template <class H>
struct CueHeaderForm;

/// How a cue lies in memory: what the zero-copy path needs to build one in a shared-memory chunk
/// (docs/zero_copy.md).
struct CueMemory {
  /// Self-contained (fixed-size members, no pointer into a heap), as Fast DDS's is_plain() says:
  /// a cue another process can read in place.
  bool plain = false;
  std::size_t size = 0;
  std::size_t alignment = 0;
  void (*construct_at)(void* where) = nullptr;              ///< a default cue at `where`
  void (*copy_to)(const void* cue, void* where) = nullptr;  ///< a copy of `cue` at `where`
};

/// What the framework needs to move a cue type it does not know at compile time.
struct CueTypeInfo {
  std::string name;  ///< the DDS type name, e.g. "oscar::GvImage"
  eprosima::fastdds::dds::TopicDataType* (*new_topic_type)() = nullptr;
  CueHeaderAccess header{};
  std::shared_ptr<void> (*make)() = nullptr;
  std::vector<std::uint8_t> (*serialize)(const void* cue) = nullptr;
  /// @throws std::runtime_error if the bytes are not a valid CDR encoding of the type.
  std::shared_ptr<void> (*deserialize)(const std::vector<std::uint8_t>& bytes) = nullptr;
  CueMemory memory{};
};

/// Registers (or finds) the description of a type by name; used by cue_type_info<T>().
const CueTypeInfo& register_cue_type(CueTypeInfo info);
/// The description of a registered type, or nullptr.
const CueTypeInfo* find_cue_type(const std::string& name);
/// Names of all registered types, sorted.
std::vector<std::string> cue_type_names();
/// How the header of a cue of that DDS type name lies in CDR: the registered type's layout
/// (the plain types are always registered), kSequences for a type this process does not know
/// (every other OSCAR cue type starts with a CueHeader).
CueHeaderLayout cue_header_layout(const std::string& type_name);

/// The first stamp of a header (its generation time), or 0 if it has none.
inline std::int64_t generation_stamp(const CueHeader& h) {
  return h.stamps().empty() ? 0 : static_cast<std::int64_t>(h.stamps().front());
}

/// Appends a stamp to a header: what a fusing module does with the cues it combines.
inline void append_stamp(CueHeader& h, std::int64_t stamp) {
  h.stamps().push_back(static_cast<unsigned long long>(stamp));
}

template <>
struct CueHeaderForm<CueHeader> {
  static constexpr CueHeaderLayout kLayout = CueHeaderLayout::kSequences;
  static constexpr std::size_t kMaxSourceLength = std::numeric_limits<std::size_t>::max();
  static std::int64_t generation_stamp(const CueHeader& h) { return oscar::generation_stamp(h); }
  static std::size_t stamp_count(const CueHeader& h) { return h.stamps().size(); }
  static CueHeader read(const CueHeader& h) { return h; }
  static std::int64_t complete(CueHeader& h, std::uint64_t seq, const std::string& source,
                               const std::function<std::int64_t()>& clock) {
    h.seq(seq);
    h.source(source);
    if (!h.stamps().empty()) return generation_stamp(h);
    const std::int64_t now = clock();
    append_stamp(h, now);
    return now;
  }
};

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
