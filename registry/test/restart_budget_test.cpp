// The restart limit counts only the restarts within its window (restart policy `max`, `window`).
#include "restart_budget.hpp"

#include <gtest/gtest.h>

namespace oscar::internal {
namespace {
using namespace std::chrono_literals;
using Clock = RestartBudget::Clock;

TEST(RestartBudget, AModuleThatFailsOverAndOverIsGivenUpAtTheLimit) {
  RestartBudget budget;
  const Clock::time_point t0{};
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(budget.allows(t0 + i * 1s, 3, 60s)) << "restart " << i + 1;
    budget.record(t0 + i * 1s);
  }
  EXPECT_FALSE(budget.allows(t0 + 3s, 3, 60s));
  EXPECT_EQ(budget.within(t0 + 3s, 60s), 3);
}

TEST(RestartBudget, FailuresSpreadOverLongerThanTheWindowAreRestartedEachTime) {
  RestartBudget budget;
  const Clock::time_point t0{};
  for (int i = 0; i < 20; ++i) {
    const auto failed_at = t0 + i * 30min;
    ASSERT_TRUE(budget.allows(failed_at, 3, 10min)) << "failure " << i + 1;
    budget.record(failed_at);
  }
  EXPECT_EQ(budget.within(t0 + 19 * 30min, 10min), 1);
}

TEST(RestartBudget, ARestartCountsUntilExactlyOneWindowHasPassed) {
  RestartBudget budget;
  const Clock::time_point t0{};
  budget.record(t0);
  EXPECT_FALSE(budget.allows(t0 + 10min - 1ms, 1, 10min));
  EXPECT_TRUE(budget.allows(t0 + 10min, 1, 10min));
}

TEST(RestartBudget, MaxZeroAllowsNoRestart) {
  RestartBudget budget;
  EXPECT_FALSE(budget.allows(Clock::time_point{}, 0, 10min));
}

}  // namespace
}  // namespace oscar::internal
