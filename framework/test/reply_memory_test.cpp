// The repeat-answer memory keeps the last reply of the senders used last, and no more of them.
#include "reply_memory.hpp"

#include <gtest/gtest.h>

#include <string>

namespace oscar::internal {
namespace {

ConfigReply reply(std::uint64_t id, const std::string& error = "") {
  ConfigReply r;
  r.id(id);
  r.module_name("m");
  r.error(error);
  return r;
}

TEST(ReplyMemory, AnswersARepeatedCommandWithTheReplyItGave) {
  ReplyMemory memory(4);
  memory.remember("coordinator", reply(7, "first"));
  const auto* again = memory.find("coordinator", 7);
  ASSERT_NE(again, nullptr);
  EXPECT_EQ(again->error(), "first");
  EXPECT_EQ(memory.find("coordinator", 8), nullptr) << "a new id is a new command";
  EXPECT_EQ(memory.find("boot", 7), nullptr) << "ids are the sender's own";
}

TEST(ReplyMemory, KeepsOneReplyPerSender) {
  ReplyMemory memory(4);
  memory.remember("boot", reply(1));
  memory.remember("boot", reply(2));
  EXPECT_EQ(memory.size(), 1u);
  EXPECT_EQ(memory.find("boot", 1), nullptr);
  EXPECT_NE(memory.find("boot", 2), nullptr);
}

TEST(ReplyMemory, ThousandsOfSendersLeaveOnlyTheCapacityUsedLast) {
  ReplyMemory memory(32);
  for (int i = 0; i < 10'000; ++i) memory.remember("sender" + std::to_string(i), reply(1));
  EXPECT_EQ(memory.size(), 32u);
  EXPECT_NE(memory.find("sender9999", 1), nullptr);
  EXPECT_NE(memory.find("sender9968", 1), nullptr);
  EXPECT_EQ(memory.find("sender9967", 1), nullptr);
}

TEST(ReplyMemory, ASenderHeardFromAgainIsForgottenLast) {
  ReplyMemory memory(2);
  memory.remember("coordinator", reply(1));
  memory.remember("boot", reply(1));
  ASSERT_NE(memory.find("coordinator", 1), nullptr);  // used again: now the newest
  memory.remember("stranger", reply(1));
  EXPECT_NE(memory.find("coordinator", 1), nullptr);
  EXPECT_EQ(memory.find("boot", 1), nullptr);
}

}  // namespace
}  // namespace oscar::internal
