#include "oscar/time.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar {
namespace {
using namespace std::chrono_literals;

TEST(Duration, ParsesEveryUnit) {
  EXPECT_EQ(parse_duration("33ms"), 33ms);
  EXPECT_EQ(parse_duration("1.5s"), 1500ms);
  EXPECT_EQ(parse_duration("200us"), 200us);
  EXPECT_EQ(parse_duration("500ns"), 500ns);
  EXPECT_EQ(parse_duration("2min"), 120s);
}

TEST(Duration, RejectsTextWithoutAUnitOrNumber) {
  for (const char* bad : {"33", "ms", "", "3 ms", "-1s", "1.2.3s", "5h"}) {
    EXPECT_THAT([&] { parse_duration(bad); }, testing::ThrowsMessage<std::invalid_argument>(
                                                  testing::HasSubstr("expected a number")))
        << bad;
  }
}

TEST(Duration, FormatsCompactly) {
  EXPECT_EQ(format_duration(33ms), "33ms");
  EXPECT_EQ(format_duration(2s), "2s");
  EXPECT_EQ(format_duration(1500us), "1500us");
  EXPECT_EQ(format_duration(7ns), "7ns");
}

}  // namespace
}  // namespace oscar
