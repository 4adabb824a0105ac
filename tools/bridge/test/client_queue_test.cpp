#include "client_queue.hpp"

#include <gtest/gtest.h>

namespace oscar::bridge {
namespace {

ClientQueue::Message message(std::uint32_t channel, std::uint8_t tag, std::size_t bytes = 1) {
  return {channel, std::make_shared<const std::vector<std::uint8_t>>(bytes, tag), tag};
}

std::vector<std::uint64_t> tags(ClientQueue& q) {
  std::vector<std::uint64_t> out;
  while (auto m = q.pop()) out.push_back(m->receive_ns);
  return out;
}

TEST(ClientQueue, PopsInArrivalOrderAcrossChannels) {
  ClientQueue q;
  q.push(message(1, 10));
  q.push(message(2, 11));
  q.push(message(1, 12));
  EXPECT_EQ(q.size(), 3u);
  EXPECT_EQ(tags(q), (std::vector<std::uint64_t>{10, 11, 12}));
  EXPECT_FALSE(q.pop());
  EXPECT_EQ(q.bytes(), 0u);
}

TEST(ClientQueue, AFullChannelLosesItsOldestAndCountsIt) {
  ClientQueue q({.messages_per_channel = 2, .bytes = 1000});
  q.push(message(1, 1));
  q.push(message(2, 2));
  q.push(message(1, 3));
  q.push(message(1, 4));
  q.push(message(1, 5));
  EXPECT_EQ(q.dropped(1), 2u);
  EXPECT_EQ(q.dropped(2), 0u);
  EXPECT_EQ(tags(q), (std::vector<std::uint64_t>{2, 4, 5})) << "the other channel keeps its own";
}

TEST(ClientQueue, OverTheByteBudgetTheChannelsOwnOldestGoesFirst) {
  ClientQueue q({.messages_per_channel = 100, .bytes = 25});
  q.push(message(1, 1, 10));
  q.push(message(2, 2, 10));
  q.push(message(2, 3, 10));  // 30 bytes: channel 2's oldest goes
  EXPECT_EQ(q.dropped(2), 1u);
  EXPECT_EQ(q.bytes(), 20u);
  EXPECT_EQ(tags(q), (std::vector<std::uint64_t>{1, 3}));
}

TEST(ClientQueue, ABigMessageAloneOnItsChannelPushesOutTheLargestOtherChannel) {
  ClientQueue q({.messages_per_channel = 100, .bytes = 100});
  q.push(message(1, 1, 30));
  q.push(message(2, 2, 10));
  q.push(message(3, 3, 80));
  EXPECT_EQ(q.dropped(1), 1u);
  EXPECT_EQ(q.dropped(3), 0u) << "the newest message is kept";
  EXPECT_EQ(tags(q), (std::vector<std::uint64_t>{2, 3}));
}

TEST(ClientQueue, TheNewestMessageIsKeptEvenIfAloneItExceedsTheBudget) {
  ClientQueue q({.messages_per_channel = 4, .bytes = 10});
  q.push(message(1, 1, 5));
  q.push(message(1, 2, 50));
  EXPECT_EQ(q.dropped(1), 1u);
  EXPECT_EQ(tags(q), (std::vector<std::uint64_t>{2}));
}

TEST(ClientQueue, ForgettingAChannelIsNoDrop) {
  ClientQueue q;
  q.push(message(1, 1, 7));
  q.push(message(2, 2, 3));
  q.forget(1);
  EXPECT_EQ(q.size(), 1u);
  EXPECT_EQ(q.bytes(), 3u);
  EXPECT_TRUE(q.drops().empty());
  EXPECT_EQ(tags(q), (std::vector<std::uint64_t>{2}));
}

}  // namespace
}  // namespace oscar::bridge
