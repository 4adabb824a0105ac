// The merged log of oscar boot and oscar log: levels are named as a module's own output names
// them, so one grep finds a warning in both.
#include "oscar/registry/log_printer.hpp"

#include <cstdio>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar {
namespace {
using testing::HasSubstr;

std::string printed(LogLevel level) {
  std::FILE* out = std::tmpfile();
  {
    LogPrinter printer(out, /*colour=*/false, /*delay_ns=*/0);
    printer.note("boot", "a line", level);
    printer.flush(/*all=*/true);
  }
  std::rewind(out);
  std::string text(4096, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), out));
  std::fclose(out);
  return text;
}

TEST(LogPrinter, NamesLevelsAsModulesDo) {
  EXPECT_THAT(printed(LOG_WARN), HasSubstr(" warning [boot] a line"));
  EXPECT_THAT(printed(LOG_CRITICAL), HasSubstr(" critical [boot] a line"));
  EXPECT_THAT(printed(LOG_INFO), HasSubstr(" info  [boot] a line"));
}

}  // namespace
}  // namespace oscar
