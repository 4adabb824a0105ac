#pragma once
/// @file Plain cues: cue types whose objects are self-contained memory (fixed-size members, no
/// pointers into a heap), so an object can live in a shared-memory chunk and another process can
/// read it in place (docs/zero_copy.md).

#include <cstddef>
#include <type_traits>

#include <oscar/plain_cues.h>
#include <oscar/plain_cuesPubSubTypes.h>

namespace oscar::zero_copy {

/// Compile-time facts about a plain cue type; specialised below for each plain type.
template <class T>
struct PlainCueTraits;

/// A type declared plain here, and laid out as plain: standard layout, no virtual functions.
/// fastddsgen 2.x writes its own copy and move operations, so std::is_trivially_copyable does not
/// hold for generated types; the size checks below show that the arrays lie inside the object.
template <class T>
concept PlainCue = requires {
  typename PlainCueTraits<T>::PubSubType;
}
&&std::is_standard_layout_v<T> && !std::is_polymorphic_v<T>;

#define OSCAR_DECLARE_PLAIN_CUE_TYPE(NAME, SHORT_NAME)         \
  template <>                                                  \
  struct PlainCueTraits<NAME> {                                \
    using PubSubType = NAME##PubSubType;                       \
    static constexpr const char* kName = "oscar::" SHORT_NAME; \
  };

OSCAR_DECLARE_PLAIN_CUE_TYPE(oscar::PlainBool, "PlainBool")
OSCAR_DECLARE_PLAIN_CUE_TYPE(oscar::PlainLineSeg3DSeq, "PlainLineSeg3DSeq")
OSCAR_DECLARE_PLAIN_CUE_TYPE(oscar::PlainGvImage, "PlainGvImage")
#undef OSCAR_DECLARE_PLAIN_CUE_TYPE

/// Lines a PlainLineSeg3DSeq holds at most, pixels a PlainGvImage holds at most (plain_cues.idl).
inline constexpr std::size_t kMaxPlainLines = 256;
inline constexpr std::size_t kMaxPlainImageBytes = 768 * 576;

// The arrays are members, not pointers: each object is at least as big as its arrays.
static_assert(sizeof(oscar::PlainCueHeader) >= 8 * 8 + 4 + 64 + 8);
static_assert(sizeof(oscar::PlainLineSeg3DSeq) >=
              sizeof(oscar::PlainCueHeader) + kMaxPlainLines * 6 * sizeof(double));
static_assert(sizeof(oscar::PlainGvImage) >= sizeof(oscar::PlainCueHeader) + kMaxPlainImageBytes);
static_assert(PlainCue<oscar::PlainBool> && PlainCue<oscar::PlainLineSeg3DSeq> &&
              PlainCue<oscar::PlainGvImage>);

}  // namespace oscar::zero_copy
