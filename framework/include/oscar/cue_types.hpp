#pragma once
/// @file The standard cue types: seed 004's benchmark types (Abb. 4, Abb. 8).

#include <stdexcept>
#include <string>
#include <string_view>

#include <oscar/bench_types.h>
#include <oscar/bench_typesPubSubTypes.h>

#include "oscar/cue.hpp"

OSCAR_DECLARE_CUE_TYPE(oscar, Bool)
OSCAR_DECLARE_CUE_TYPE(oscar, LineSeg3DSeq)
OSCAR_DECLARE_CUE_TYPE(oscar, GvImage)

namespace oscar {
/// Registers the standard types so they can be found by name (oscar-run, record, echo).
void register_standard_cue_types();
}  // namespace oscar

namespace oscar {
/// Calls `f.template operator()<T>()` with the standard cue type named `name` ("Bool" or
/// "oscar::Bool", "LineSeg3DSeq", "GvImage"): how kernels that relay any standard type pick one.
/// @throws std::invalid_argument for any other name, listing the standard types.
template <class F>
decltype(auto) visit_standard_type(std::string_view name, F&& f) {
  if (name.starts_with("oscar::")) name.remove_prefix(7);
  if (name == "Bool") return f.template operator()<Bool>();
  if (name == "LineSeg3DSeq") return f.template operator()<LineSeg3DSeq>();
  if (name == "GvImage") return f.template operator()<GvImage>();
  throw std::invalid_argument("cue type '" + std::string(name) +
                              "' is not a standard type (Bool, LineSeg3DSeq, GvImage)");
}
}  // namespace oscar
