#pragma once
// The message of the std::invalid_argument a call throws, for tests that check error messages.

#include <stdexcept>
#include <string>

namespace oscar::applets::testing {

template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no exception";
}

}  // namespace oscar::applets::testing
