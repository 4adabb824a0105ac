#pragma once
/// @file OSCAR_DEMAND: an always-on check for bugs in OSCAR's own code.

#include <source_location>
#include <string_view>

namespace oscar::internal {
[[noreturn]] void demand_failed(std::string_view condition, std::string_view message,
                                std::source_location where);
}  // namespace oscar::internal

/// Aborts with the condition, the message and the source location when `condition` is false.
/// For broken invariants of OSCAR itself; bad input and misuse throw instead.
#define OSCAR_DEMAND(condition, message)                                                      \
  do {                                                                                        \
    if (!(condition)) [[unlikely]] {                                                          \
      ::oscar::internal::demand_failed(#condition, message, std::source_location::current()); \
    }                                                                                         \
  } while (false)
