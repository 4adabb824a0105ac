#pragma once
// The JSON schemas the bridge advertises, compiled in from tools/bridge/schemas/: the fields of
// Foxglove's message types it sends (foxglove.*.json, following Foxglove's published schemas;
// the Foxglove test checks them against the npm package @foxglove/schemas) and its own types
// (oscar.*.json).

#include <string>
#include <string_view>

namespace oscar::bridge {

/// The schema `name` (e.g. "foxglove.RawImage"), as compact JSON text.
/// @throws std::out_of_range naming it if there is no such schema (a bug).
const std::string& json_schema(std::string_view name);

}  // namespace oscar::bridge
