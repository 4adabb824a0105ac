#pragma once
// Shared by the swarm tests: an error test checks the message, not only that there is one.

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace oscar::swarm::test {

/// Runs `f` and expects std::invalid_argument whose message contains `part`.
template <typename F>
void expect_error(F f, const std::string& part) {
  try {
    f();
    FAIL() << "no exception; expected one mentioning '" << part << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

}  // namespace oscar::swarm::test
