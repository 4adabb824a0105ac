#pragma once
// Runs one of OSCAR's programs (build/bin) to its end and returns its output (stdout and
// stderr); a test failure if it exits otherwise than expected or hangs.
#include <chrono>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "process.hpp"

namespace oscar::test {

inline std::string run_tool(std::vector<std::string> argv, int expected_exit = 0) {
  const auto log = temp_path("tool_" + argv.front()) + ".log";
  argv.front() = bin(argv.front());
  Process p(argv, log);
  const auto rc = p.wait(std::chrono::seconds(60));
  EXPECT_EQ(rc, expected_exit) << p.output();
  return p.output();
}

}  // namespace oscar::test
