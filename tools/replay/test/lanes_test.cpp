#include "lanes.hpp"

#include <gtest/gtest.h>
#include <sys/prctl.h>

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

namespace oscar::replay {
namespace {
using namespace std::chrono_literals;
using Clock = Lanes::Clock;

// What the lanes published: per lane, the payload's first byte and when it was published.
struct Published {
  std::mutex mutex;
  std::map<const void*, std::vector<std::pair<int, Clock::time_point>>> by_lane;
};

Pending message(const void* lane, std::chrono::nanoseconds due, int id, std::size_t size,
                Published& out) {
  Pending p;
  p.lane = lane;
  p.due = due;
  p.bytes.assign(size, static_cast<std::uint8_t>(id));
  p.publish = [&out, lane](std::vector<std::uint8_t>& bytes) {
    std::lock_guard lock(out.mutex);
    out.by_lane[lane].emplace_back(bytes.front(), Clock::now());
  };
  return p;
}

TEST(Lanes, PublishEachLaneInOrderNeverBeforeItsDueTime) {
  const std::atomic<bool> stop{false};
  Published out;
  const int a = 0, b = 0;
  const auto start = Clock::now() + 20ms;
  {
    Lanes lanes({&a, &b}, start, 1 << 20, stop);
    for (int i = 0; i < 20; ++i) {
      ASSERT_TRUE(lanes.add(message(&a, i * 2ms, i, 8, out)));
      ASSERT_TRUE(lanes.add(message(&b, i * 2ms + 1ms, 100 + i, 8, out)));
    }
    lanes.drain();
    EXPECT_EQ(lanes.published(), 40u);
  }
  for (const auto* lane : {&a, &b}) {
    const auto& got = out.by_lane[lane];
    ASSERT_EQ(got.size(), 20u);
    for (int i = 0; i < 20; ++i) {
      const int first = lane == &a ? 0 : 100;
      EXPECT_EQ(got[i].first, first + i);
      const auto due = start + i * 2ms + (lane == &a ? 0ms : 1ms);
      EXPECT_GE(got[i].second, due) << "message " << i << " was published early";
    }
  }
}

TEST(Lanes, PublishWithoutTimerSlack) {
  // Linux may wake a sleeping thread up to its timer slack late (50 us by default).
  const std::atomic<bool> stop{false};
  const int lane = 0;
  std::atomic<long> slack_ns{-1};
  {
    Lanes lanes({&lane}, Clock::now(), 1 << 20, stop);
    Pending p;
    p.lane = &lane;
    p.bytes.assign(1, 0);
    p.publish = [&](std::vector<std::uint8_t>&) {
      slack_ns = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
    };
    ASSERT_TRUE(lanes.add(std::move(p)));
    lanes.drain();
  }
  EXPECT_EQ(slack_ns, 1);
}

TEST(Lanes, AFullReaderWaitsUntilHalfOfWhatIsAheadIsPublished) {
  // 10 messages of 10 bytes fill 100 bytes of read-ahead; the 11th waits until the lane has
  // published at least half (waking the reader after every message cost a context switch each).
  const std::atomic<bool> stop{false};
  Published out;
  const int lane = 0;
  Lanes lanes({&lane}, Clock::now() + 50ms, 100, stop);  // nothing due before the 11th is read
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(lanes.add(message(&lane, i * 5ms, i, 10, out)));
  ASSERT_TRUE(lanes.add(message(&lane, 50ms, 10, 10, out)));
  EXPECT_GE(lanes.published(), 5u);
  lanes.drain();
  EXPECT_EQ(lanes.published(), 11u);
}

TEST(Lanes, AStopEndsTheWaitsForRoomAndForDueTimes) {
  std::atomic<bool> stop{false};
  Published out;
  const int lane = 0;
  Lanes lanes({&lane}, Clock::now(), 10, stop);
  ASSERT_TRUE(lanes.add(message(&lane, 1h, 0, 10, out)));  // fills the read-ahead
  const auto t0 = Clock::now();
  std::thread stopper([&] {
    std::this_thread::sleep_for(50ms);
    stop = true;
  });
  EXPECT_FALSE(lanes.add(message(&lane, 1h, 1, 10, out)));
  lanes.drain();
  stopper.join();
  EXPECT_LT(Clock::now() - t0, 1s);
  EXPECT_EQ(lanes.published(), 0u);
}

TEST(Lanes, DestroyingThemDropsWhatIsNotDueYet) {
  const std::atomic<bool> stop{false};
  Published out;
  const int lane = 0;
  const auto t0 = Clock::now();
  {
    Lanes lanes({&lane}, Clock::now(), 1 << 20, stop);
    ASSERT_TRUE(lanes.add(message(&lane, 0ms, 0, 8, out)));
    ASSERT_TRUE(lanes.add(message(&lane, 1h, 1, 8, out)));
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_LT(Clock::now() - t0, 1s);
  ASSERT_EQ(out.by_lane[&lane].size(), 1u);
  EXPECT_EQ(out.by_lane[&lane][0].first, 0);
}

TEST(Lanes, TellTheReaderWhenItIsFarAheadAndWhenItFallsBehind) {
  const std::atomic<bool> stop{false};
  Published out;
  const int lane = 0;
  std::atomic<int> ahead{0}, behind{0};
  Lanes lanes({&lane}, Clock::now() + 50ms, 100, stop, {},
              ReadingPace{[&] { ++ahead; }, [&] { ++behind; }});
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(lanes.add(message(&lane, i * 5ms, i, 10, out)));
  EXPECT_EQ(ahead, 0);
  ASSERT_TRUE(lanes.add(message(&lane, 50ms, 10, 10, out)));  // full: waits for half
  EXPECT_EQ(ahead, 1);
  EXPECT_EQ(behind, 0);
  // Nothing more is read: the queue falls below a quarter (25 bytes) while reading goes on.
  const auto until = Clock::now() + 2s;
  while (behind == 0 && Clock::now() < until) std::this_thread::sleep_for(5ms);
  EXPECT_EQ(behind, 1);
  lanes.drain();
}

TEST(Lanes, AMessageForALaneNotGivenIsAnError) {
  const std::atomic<bool> stop{false};
  Published out;
  const int lane = 0, other = 0;
  Lanes lanes({&lane}, Clock::now(), 100, stop);
  EXPECT_THROW(lanes.add(message(&other, 0ms, 0, 1, out)), std::invalid_argument);
}

}  // namespace
}  // namespace oscar::replay
