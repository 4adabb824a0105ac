// The topic catalogue (oscar/topics.hpp): both sides of every topic take the catalogue's QoS, so
// a writer and a reader made from one entry must match. A reader asking for more than the
// writer offers (reliable from best effort, transient-local from volatile, a shorter lease)
// would silently never match.
#include "oscar/topics.hpp"

#include <unistd.h>

#include <atomic>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"
#include "process.hpp"  // tests/common

namespace oscar {
namespace {
using namespace std::chrono_literals;

template <class T, class PubSubType>
void expect_both_sides_match(DdsParticipant& p, const TopicSpec<T, PubSubType>& spec) {
  TopicWriter<T, PubSubType> writer(p, spec);
  TopicReader<T, PubSubType> reader(p, spec, [](const T&, const auto&) {});
  EXPECT_TRUE(eventually([&] { return writer.matched() > 0 && reader.matched() > 0; }, 5s))
      << spec.name << ": its writer and reader QoS do not match";
}

TEST(Topics, TheWriterAndReaderOfEveryCatalogueTopicMatch) {
  DdsParticipant p(oscar::test::test_domain(), "test:topics");
  expect_both_sides_match(p, topics::config("m"));
  expect_both_sides_match(p, topics::config_reply("m"));
  expect_both_sides_match(p, topics::log());
  expect_both_sides_match(p, topics::module_state());
  expect_both_sides_match(p, topics::module_alive(300ms));
  expect_both_sides_match(p, topics::monitor_alive(300ms));
  expect_both_sides_match(p, topics::process_events());
  expect_both_sides_match(p, topics::launch());
  expect_both_sides_match(p, topics::registry_request());
  expect_both_sides_match(p, topics::registry_reply());
  expect_both_sides_match(p, topics::system_state());
  expect_both_sides_match(p, topics::applet_plan());
  expect_both_sides_match(p, topics::sched_hello());
  expect_both_sides_match(p, topics::sched_beat());
  expect_both_sides_match(p, topics::sched_call());
  expect_both_sides_match(p, topics::sched_reply());
  expect_both_sides_match(p, topics::sched_notice());
  expect_both_sides_match(p, topics::sched_command());
  expect_both_sides_match(p, topics::sched_command_reply());
  expect_both_sides_match(p, topics::sched_wishes());
  expect_both_sides_match(p, topics::swarm_request());
  expect_both_sides_match(p, topics::swarm_reply());
  expect_both_sides_match(p, topics::swarm_status());
  expect_both_sides_match(p, topics::swarm_plan());
  expect_both_sides_match(p, topics::pull_request("k/out"));
  expect_both_sides_match(p, topics::pull_reply("k/out"));
}

TEST(Topics, EveryCatalogueTopicHasANameOfItsOwn) {
  const std::set<std::string> names{topics::config("m").name,
                                    topics::config_reply("m").name,
                                    topics::log().name,
                                    topics::module_state().name,
                                    topics::module_alive(1s).name,
                                    topics::monitor_alive(1s).name,
                                    topics::process_events().name,
                                    topics::launch().name,
                                    topics::registry_request().name,
                                    topics::registry_reply().name,
                                    topics::system_state().name,
                                    topics::applet_plan().name,
                                    topics::sched_hello().name,
                                    topics::sched_beat().name,
                                    topics::sched_call().name,
                                    topics::sched_reply().name,
                                    topics::sched_notice().name,
                                    topics::sched_command().name,
                                    topics::sched_command_reply().name,
                                    topics::sched_wishes().name,
                                    topics::swarm_request().name,
                                    topics::swarm_reply().name,
                                    topics::swarm_status().name,
                                    topics::swarm_plan().name,
                                    topics::pull_request("k/out").name,
                                    topics::pull_reply("k/out").name,
                                    topics::cue("k/out")};
  EXPECT_EQ(names.size(), 27u);
}

// A module's first log lines are written before boot's reader has discovered it (its process
// has just started): they must still reach boot's merged log.
TEST(Topics, ALogReaderThatMatchesLateGetsTheLinesWrittenBefore) {
  DdsParticipant p(oscar::test::test_domain(), "test:topics");
  TopicWriter<LogRecord, LogRecordPubSubType> writer(p, topics::log());
  for (int i = 0; i < 3; ++i) {
    LogRecord r;
    r.module_name("early");
    r.message("line " + std::to_string(i));
    writer.write(r);
  }
  std::mutex mutex;
  std::vector<std::string> got;
  TopicReader<LogRecord, LogRecordPubSubType> reader(p, topics::log(),
                                                     [&](const LogRecord& r, const auto&) {
                                                       std::lock_guard lock(mutex);
                                                       got.push_back(r.message());
                                                     });
  EXPECT_TRUE(eventually(
      [&] {
        std::lock_guard lock(mutex);
        return got.size() == 3;
      },
      5s));
  std::lock_guard lock(mutex);
  EXPECT_EQ(got, (std::vector<std::string>{"line 0", "line 1", "line 2"}));
}

// A requester's reader matches the replier's writer before that writer has matched the reader
// (each side learns of the other on its own): a reply written in between must still arrive.
template <class T, class PubSubType>
void expect_a_late_reader_gets_the_reply(DdsParticipant& p, const TopicSpec<T, PubSubType>& spec) {
  TopicWriter<T, PubSubType> writer(p, spec);
  T reply;
  reply.id(42);
  writer.write(reply);
  std::atomic<unsigned long long> got{0};
  TopicReader<T, PubSubType> reader(p, spec, [&](const T& r, const auto&) { got = r.id(); });
  EXPECT_TRUE(eventually([&] { return got == 42; }, 5s))
      << spec.name << ": a reply written before the requester's reader matched was lost";
}

TEST(Topics, AReplyWrittenBeforeTheRequesterMatchedReachesIt) {
  DdsParticipant p(oscar::test::test_domain(), "test:topics");
  expect_a_late_reader_gets_the_reply(p, topics::config_reply("m"));
  expect_a_late_reader_gets_the_reply(p, topics::registry_reply());
}

TEST(Topics, ASwarmReplyWrittenBeforeTheRequesterMatchedReachesIt) {
  DdsParticipant p(oscar::test::test_domain(), "test:topics");
  TopicWriter<SwarmReply, SwarmReplyPubSubType> writer(p, topics::swarm_reply());
  SwarmReply reply;
  reply.request(42);
  writer.write(reply);
  std::atomic<unsigned long long> got{0};
  TopicReader<SwarmReply, SwarmReplyPubSubType> reader(
      p, topics::swarm_reply(), [&](const SwarmReply& r, const auto&) { got = r.request(); });
  EXPECT_TRUE(eventually([&] { return got == 42; }, 5s))
      << "a swarm reply written before `oscar swarm`'s reader matched was lost";
}

TEST(Topics, CueTopicsAreNamedAfterTheirOutput) {
  EXPECT_EQ(topics::cue("cam/image"), "oscar/cue/cam/image");
  EXPECT_TRUE(topics::is_cue("oscar/cue/cam/image"));
  EXPECT_FALSE(topics::is_cue("oscar/config/cam"));
  EXPECT_FALSE(topics::is_cue("oscar/cuex"));
}

}  // namespace
}  // namespace oscar
