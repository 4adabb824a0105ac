#include "reading_priority.hpp"

#include <sched.h>

#include <gtest/gtest.h>

#include <thread>

namespace oscar::replay {
namespace {

TEST(ReadingPriority, BackgroundIsSchedIdleAndNormalUndoesIt) {
  std::thread reading([] {
    const ReadingPriority priority;
    if (!priority.available()) {
      GTEST_SKIP() << "this process may not leave SCHED_IDLE (no CAP_SYS_NICE, RLIMIT_NICE < 20)";
    }
    // As a lane does it: from another thread.
    std::thread([&] { priority.background(); }).join();
    EXPECT_EQ(sched_getscheduler(0), SCHED_IDLE);
    std::thread([&] { priority.normal(); }).join();
    EXPECT_EQ(sched_getscheduler(0), SCHED_OTHER);
    priority.background();
  });
  reading.join();
}

TEST(ReadingPriority, TheThreadIsNormalAgainWhenItEnds) {
  std::thread reading([] {
    {
      const ReadingPriority priority;
      priority.background();
    }
    EXPECT_EQ(sched_getscheduler(0), SCHED_OTHER);
  });
  reading.join();
}

TEST(ReadingPriority, ItReturnsToTheSchedulingTheThreadHad) {
  std::thread reading([] {
    sched_param fifo{};
    fifo.sched_priority = 1;
    if (sched_setscheduler(0, SCHED_FIFO, &fifo) != 0) {
      GTEST_SKIP() << "this process may not use SCHED_FIFO";
    }
    {
      const ReadingPriority priority;
      ASSERT_TRUE(priority.available());
      priority.background();
      EXPECT_EQ(sched_getscheduler(0), SCHED_IDLE);
      priority.normal();
      EXPECT_EQ(sched_getscheduler(0), SCHED_FIFO);
      priority.background();
    }
    EXPECT_EQ(sched_getscheduler(0), SCHED_FIFO);
  });
  reading.join();
}

}  // namespace
}  // namespace oscar::replay
