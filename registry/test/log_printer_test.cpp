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

LogRecord record(unsigned long long stamp_ns, const std::string& module,
                 const std::string& message) {
  LogRecord r;
  r.stamp_ns(stamp_ns);
  r.module_name(module);
  r.level(LOG_INFO);
  r.message(message);
  return r;
}

std::string read_all(std::FILE* out) {
  std::rewind(out);
  std::string text(8192, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), out));
  return text;
}

TEST(LogPrinter, OrdersRecordsByTheirHostsCorrectedTime) {
  std::FILE* out = std::tmpfile();
  {
    LogPrinter printer(out, /*colour=*/false, /*delay_ns=*/0);
    printer.module_host("camera", "fast");
    printer.module_host("planner", "base");
    // fast's clock is 250 ms ahead: its record stamped 1.200 s happened at 0.950 s, before the
    // planner's at 1.000 s.
    printer.host_clock("fast", std::chrono::milliseconds(250), std::chrono::milliseconds(1));
    printer.add(record(1'000'000'000, "planner", "second"));
    printer.add(record(1'200'000'000, "camera", "first"));
    printer.flush(/*all=*/true);
  }
  const auto text = read_all(out);
  std::fclose(out);
  const auto first = text.find("[camera] first");
  const auto second = text.find("[planner] second");
  ASSERT_NE(first, std::string::npos) << text;
  ASSERT_NE(second, std::string::npos) << text;
  EXPECT_LT(first, second) << text;
  EXPECT_THAT(text, HasSubstr(".950 info  [camera] first"));  // printed with the corrected time
}

TEST(LogPrinter, ReordersRecordsHeldBackWhenTheirHostsFirstEstimateComes) {
  std::FILE* out = std::tmpfile();
  {
    LogPrinter printer(out, /*colour=*/false, /*delay_ns=*/0);
    printer.module_host("camera", "fast");
    printer.add(record(1'000'000'000, "planner", "second"));
    printer.add(record(1'200'000'000, "camera", "first"));  // before fast's first estimate
    printer.host_clock("fast", std::chrono::milliseconds(250), std::chrono::milliseconds(1));
    printer.flush(/*all=*/true);
  }
  const auto text = read_all(out);
  std::fclose(out);
  EXPECT_LT(text.find("[camera] first"), text.find("[planner] second")) << text;
  EXPECT_THAT(text, HasSubstr(".950 info  [camera] first"));
}

TEST(LogPrinter, KeepsStampsOfHostsWithoutAnEstimate) {
  std::FILE* out = std::tmpfile();
  {
    LogPrinter printer(out, /*colour=*/false, /*delay_ns=*/0);
    printer.module_host("camera", "fast");
    printer.add(record(1'000'000'000, "planner", "first"));
    printer.add(record(1'200'000'000, "camera", "second"));
    printer.flush(/*all=*/true);
  }
  const auto text = read_all(out);
  std::fclose(out);
  EXPECT_LT(text.find("[planner] first"), text.find("[camera] second")) << text;
  EXPECT_THAT(text, HasSubstr(".200 info  [camera] second"));
}

TEST(LogPrinter, SaysOnceWhenAHostsClockIsMoreThanTenMillisecondsOff) {
  std::FILE* out = std::tmpfile();
  {
    LogPrinter printer(out, /*colour=*/false, /*delay_ns=*/0);
    printer.host_clock("base", std::chrono::milliseconds(2), std::chrono::milliseconds(1));
    printer.host_clock("fast", std::chrono::milliseconds(-30), std::chrono::milliseconds(1));
    printer.host_clock("fast", std::chrono::milliseconds(-31), std::chrono::milliseconds(1));
    printer.flush(/*all=*/true);
  }
  const auto text = read_all(out);
  std::fclose(out);
  EXPECT_THAT(text, HasSubstr("warning [clocks] host fast's clock is -30.0 ms (± 1.0 ms)"));
  EXPECT_THAT(text, HasSubstr("chrony or PTP"));
  EXPECT_EQ(text.find("host fast"), text.rfind("host fast")) << text;
  EXPECT_EQ(text.find("host base"), std::string::npos) << text;
}

}  // namespace
}  // namespace oscar
