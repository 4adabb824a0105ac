#pragma once
/// @file Waiting in a test for something another thread or process does.

#include <chrono>
#include <thread>

namespace oscar {

/// Polls `condition` every `poll` until it holds (true) or `limit` has passed (false).
template <class Condition>
bool eventually(Condition&& condition, std::chrono::milliseconds limit = std::chrono::seconds(10),
                std::chrono::milliseconds poll = std::chrono::milliseconds(2)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(poll);
  }
  return true;
}

}  // namespace oscar
