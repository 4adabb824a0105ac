#pragma once
/// @file Time stamps and durations as OSCAR uses them on the wire and in configuration.

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

namespace oscar {

/// Nanoseconds since the Unix epoch (system clock): the unit of every cue stamp
/// (docs/architecture.md, "Topics and QoS classes").
using Stamp = std::int64_t;

/// The current wall-clock time as a Stamp. Kernels get their time from the Cycle instead.
Stamp wall_now();

/// Parses a duration such as "33ms", "1.5s", "200us", "500ns", "2min".
/// @throws std::invalid_argument naming the text and the accepted units.
std::chrono::nanoseconds parse_duration(std::string_view text);

/// Formats a duration compactly ("33ms", "1.5s", "250us").
std::string format_duration(std::chrono::nanoseconds d);

}  // namespace oscar
