// Each writer of configuration commands gets a burst and an average rate; its excess is dropped,
// counted and reported at most once a second, and other writers are not affected.
#include "command_rate_limit.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar::internal {
namespace {
using namespace std::chrono_literals;
using testing::HasSubstr;
using Clock = CommandRateLimit::Clock;

int admitted(CommandRateLimit& limit, const std::string& writer, int commands,
             Clock::time_point at) {
  int n = 0;
  for (int i = 0; i < commands; ++i) n += limit.admit(writer, at) ? 1 : 0;
  return n;
}

TEST(CommandRateLimit, AWriterGetsItsBurstAtOnceAndThenItsRate) {
  CommandRateLimit limit({.per_second = 100, .burst = 200});
  const Clock::time_point t0{};
  EXPECT_EQ(admitted(limit, "flood", 5000, t0), 200);
  EXPECT_EQ(limit.dropped(), 4800u);
  EXPECT_EQ(admitted(limit, "flood", 5000, t0 + 100ms), 10);
  EXPECT_EQ(admitted(limit, "flood", 5000, t0 + 10s), 200) << "the bucket holds a burst at most";
}

TEST(CommandRateLimit, AFloodingWriterDoesNotSpendAnotherWritersBudget) {
  CommandRateLimit limit({.per_second = 100, .burst = 200});
  const Clock::time_point t0{};
  admitted(limit, "flood", 100'000, t0);
  EXPECT_TRUE(limit.admit("coordinator", t0));
}

TEST(CommandRateLimit, DropsAreReportedAtMostOnceASecondWithTheirWriter) {
  CommandRateLimit limit({.per_second = 100, .burst = 200});
  const Clock::time_point t0{};
  EXPECT_EQ(limit.report(t0), std::nullopt) << "nothing dropped";
  admitted(limit, "flood", 250, t0);
  const auto line = limit.report(t0);
  ASSERT_TRUE(line);
  EXPECT_THAT(*line, HasSubstr("dropped 50 configuration command(s) over the rate limit of 100/s "
                               "(burst 200) per writer: 50 from writer flood"));
  admitted(limit, "flood", 10, t0 + 10ms);
  EXPECT_EQ(limit.report(t0 + 500ms), std::nullopt) << "one line a second";
  EXPECT_THAT(limit.report(t0 + 1s), testing::Optional(HasSubstr("dropped 9 ")));
}

TEST(CommandRateLimit, TracksNoMoreWritersThanItsCapacity) {
  CommandRateLimit limit({.per_second = 100, .burst = 1}, 8);
  const Clock::time_point t0{};
  for (int i = 0; i < 1000; ++i) {
    limit.admit("writer" + std::to_string(i), t0);
    limit.admit("writer" + std::to_string(i), t0);  // dropped
  }
  EXPECT_EQ(limit.tracked(), 8u);
  EXPECT_THAT(limit.report(t0), testing::Optional(HasSubstr("992 from writers no longer tracked")));
}

}  // namespace
}  // namespace oscar::internal
