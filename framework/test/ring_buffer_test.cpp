#include "oscar/ring_buffer.hpp"

#include <atomic>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar {
namespace {

std::shared_ptr<const void> cue(int v) { return std::make_shared<const int>(v); }
int value(const RingEntry& e) { return *std::static_pointer_cast<const int>(e.cue); }
std::vector<int> values(const std::vector<RingEntry>& es) {
  std::vector<int> out;
  for (const auto& e : es) out.push_back(value(e));
  return out;
}

// Pushes cues 1..n stamped 10, 20, 30, ...
void fill(RingBuffer& rb, int n) {
  for (int i = 1; i <= n; ++i) rb.push(cue(i), 10 * i, 0);
}

TEST(RingBuffer, RejectsDepthZero) {
  EXPECT_THAT([] { RingBuffer rb(0); },
              testing::ThrowsMessage<std::invalid_argument>(testing::HasSubstr("at least 1")));
}

TEST(RingBuffer, EveryQueryIsEmptyWhenNothingWasWritten) {
  RingBuffer rb(4);
  EXPECT_FALSE(rb.latest());
  EXPECT_TRUE(rb.latest(3).empty());
  EXPECT_FALSE(rb.at_or_before(100));
  EXPECT_FALSE(rb.nearest(100));
  EXPECT_TRUE(rb.range(0, 100).empty());
  EXPECT_FALSE(rb.wait_next(0, std::chrono::milliseconds(1)));
}

TEST(RingBuffer, WrapAroundKeepsTheNewestDepthCues) {
  RingBuffer rb(3);
  fill(rb, 5);
  EXPECT_EQ(rb.size(), 3u);
  EXPECT_EQ(rb.pushed(), 5u);
  EXPECT_EQ(value(*rb.latest()), 5);
  EXPECT_THAT(values(rb.latest(10)), testing::ElementsAre(3, 4, 5));
  EXPECT_THAT(values(rb.latest(2)), testing::ElementsAre(4, 5));
}

TEST(RingBuffer, DropOldestIfFullMakesRoomOnlyInAFullRing) {
  RingBuffer rb(3);
  fill(rb, 2);
  EXPECT_EQ(rb.drop_oldest_if_full(), nullptr);
  EXPECT_EQ(rb.size(), 2u);
  rb.push(cue(3), 30, 0);
  const auto dropped = rb.drop_oldest_if_full();
  ASSERT_NE(dropped, nullptr);
  EXPECT_EQ(*std::static_pointer_cast<const int>(dropped), 1);
  EXPECT_EQ(dropped.use_count(), 1) << "the ring holds it no more";
  EXPECT_THAT(values(rb.latest(10)), testing::ElementsAre(2, 3));
  EXPECT_EQ(rb.push(cue(4), 40, 0), nullptr) << "room was made: nothing to evict";
  EXPECT_THAT(values(rb.latest(10)), testing::ElementsAre(2, 3, 4));
  EXPECT_EQ(value(*rb.wait_next(2, std::chrono::milliseconds(0))), 3);
  EXPECT_EQ(rb.pushed(), 4u);
}

TEST(RingBuffer, AtOrBeforeFindsTheNewestNotAfterT) {
  RingBuffer rb(3);
  fill(rb, 5);  // holds 30, 40, 50
  EXPECT_EQ(value(*rb.at_or_before(45)), 4);
  EXPECT_EQ(value(*rb.at_or_before(40)), 4);
  EXPECT_EQ(value(*rb.at_or_before(1000)), 5);
  EXPECT_FALSE(rb.at_or_before(29)) << "cue 2 (t=20) was evicted";
}

TEST(RingBuffer, NearestPrefersTheOlderOnATie) {
  RingBuffer rb(3);
  fill(rb, 5);
  EXPECT_EQ(value(*rb.nearest(44)), 4);
  EXPECT_EQ(value(*rb.nearest(46)), 5);
  EXPECT_EQ(value(*rb.nearest(45)), 4);
  EXPECT_EQ(value(*rb.nearest(0)), 3);
}

TEST(RingBuffer, RangeIsInclusiveAndSortedByTime) {
  RingBuffer rb(8);
  rb.push(cue(1), 30, 0);
  rb.push(cue(2), 10, 0);  // older stamp arriving later (a rewired input)
  rb.push(cue(3), 20, 0);
  EXPECT_THAT(values(rb.range(10, 20)), testing::ElementsAre(2, 3));
  EXPECT_THAT(values(rb.range(0, 100)), testing::ElementsAre(2, 3, 1));
  EXPECT_EQ(value(*rb.at_or_before(25)), 3);
}

TEST(RingBuffer, InvertedRangeIsAnError) {
  RingBuffer rb(3);
  fill(rb, 2);
  EXPECT_THAT([&] { rb.range(20, 10); }, testing::ThrowsMessage<std::invalid_argument>(
                                             testing::HasSubstr("inverted time range [20, 10]")));
}

TEST(RingBuffer, WaitNextReturnsTheNextUnseenCue) {
  RingBuffer rb(8);
  fill(rb, 2);
  auto first = rb.wait_next(0, std::chrono::milliseconds(1));
  ASSERT_TRUE(first);
  EXPECT_EQ(value(*first), 1);
  auto second = rb.wait_next(first->index, std::chrono::milliseconds(1));
  EXPECT_EQ(value(*second), 2);
  EXPECT_FALSE(rb.wait_next(second->index, std::chrono::milliseconds(1)));
}

// Woken by the push, not found when the wait timed out: a push skips the wake-up when nobody
// waits, so these check it is not skipped when someone does.
constexpr auto kLongWait = std::chrono::seconds(60);

TEST(RingBuffer, WaitNextWakesWhenACueArrives) {
  RingBuffer rb(2);
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    rb.push(cue(7), 70, 0);
  });
  const auto start = std::chrono::steady_clock::now();
  auto e = rb.wait_next(0, kLongWait);
  EXPECT_LT(std::chrono::steady_clock::now() - start, kLongWait / 2) << "woken, not timed out";
  producer.join();
  ASSERT_TRUE(e);
  EXPECT_EQ(value(*e), 7);
}

TEST(RingBuffer, OnePushWakesEveryWaiter) {
  RingBuffer rb(2);
  std::atomic<int> woken{0};
  std::vector<std::thread> waiters;
  for (int i = 0; i < 3; ++i) {
    waiters.emplace_back([&] {
      const auto start = std::chrono::steady_clock::now();
      const auto e = rb.wait_next(0, kLongWait);
      if (e && value(*e) == 7 && std::chrono::steady_clock::now() - start < kLongWait / 2) ++woken;
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // most likely all wait by now
  rb.push(cue(7), 70, 0);
  for (auto& t : waiters) t.join();
  EXPECT_EQ(woken, 3);
}

TEST(RingBuffer, SkipsToTheOldestHeldWhenTheNextWasEvicted) {
  RingBuffer rb(3);
  fill(rb, 5);  // 1 and 2 evicted
  EXPECT_EQ(value(*rb.wait_next(0, std::chrono::milliseconds(1))), 3);
}

TEST(RingBuffer, ConcurrentProducersAndConsumersSeeEveryIndexInOrder) {
  RingBuffer rb(64);
  constexpr int kPerProducer = 20000;
  std::atomic<bool> done{false};
  std::vector<std::thread> producers;
  for (int p = 0; p < 2; ++p) {
    producers.emplace_back([&, p] {
      for (int i = 0; i < kPerProducer; ++i) rb.push(cue(p * kPerProducer + i), i, 0);
    });
  }
  std::uint64_t last = 0;
  bool ordered = true;
  std::thread consumer([&] {
    while (!done || last < rb.pushed()) {
      auto e = rb.wait_next(last, std::chrono::milliseconds(5));
      if (!e) continue;
      ordered = ordered && e->index > last;
      last = e->index;
      (void)rb.latest(8);
      (void)rb.nearest(100);
    }
  });
  for (auto& t : producers) t.join();
  done = true;
  consumer.join();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(rb.pushed(), 2u * kPerProducer);
  EXPECT_EQ(last, 2u * kPerProducer);
}

}  // namespace
}  // namespace oscar
