// oscar record across real processes: bench_source modules publish known cues of the three seed
// types, the recorder writes them to MCAP, our reader checks every cue arrived whole and in
// order; a recorder killed with SIGKILL leaves a file `oscar info` reads (issue 4).
#include <csignal>
#include <filesystem>
#include <functional>
#include <map>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/config_client.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/mcap/reader.hpp"
#include "oscar/mcap/writer.hpp"
#include "oscar/testing/eventually.hpp"
#include "process.hpp"  // tests/common

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::Process;
using testing::ContainsRegex;
using testing::HasSubstr;

std::unique_ptr<Process> source(const std::string& name, const std::string& type, int count,
                                const std::string& mode) {
  return std::make_unique<Process>(
      std::vector<std::string>{test::bin("oscar-run"), "--name", name, "--domain",
                               std::to_string(test::test_domain()), "-k", "bench_source:" + name,
                               "-p", name + ".type=" + type, "-p",
                               name + ".count=" + std::to_string(count), "-m", mode},
      test::temp_path(name + ".log"));
}

std::unique_ptr<Process> recorder(const std::string& file, std::vector<std::string> args) {
  std::vector<std::string> argv{test::bin("oscar-record"), "-o", file, "--domain",
                                std::to_string(test::test_domain())};
  argv.insert(argv.end(), args.begin(), args.end());
  return std::make_unique<Process>(argv, test::temp_path("record.log"));
}

// The cue bench_source publishes (its prototype), given the header the recording carries.
template <class T>
bool same_payload(const T& recorded);
template <>
bool same_payload(const Bool& b) {
  return b.value();
}
template <>
bool same_payload(const LineSeg3DSeq& s) {
  if (s.lines().size() != 100) return false;
  for (std::size_t i = 0; i < s.lines().size(); ++i) {
    const auto& l = s.lines()[i];
    if (l.sx() != i || l.sy() != 0.5 * i || l.ez() != 1.0 || l.ex() != i + 1.0) return false;
  }
  return true;
}
template <>
bool same_payload(const GvImage& g) {
  if (g.dx() != 768 || g.dy() != 576 || g.image().size() != 768u * 576u) return false;
  for (std::size_t k = 0; k < g.image().size(); k += 997) {
    if (g.image()[k] != static_cast<std::uint8_t>((k % 768 + k / 768) & 0xff)) return false;
  }
  return true;
}

// Decodes every recorded message of a topic with the compiled type and checks it: payload as
// published, source and seq in its header, the bytes re-encode identically; returns the seqs.
template <class T>
std::vector<std::uint64_t> check_topic(const std::string& file, const std::string& kernel) {
  std::vector<std::uint64_t> seqs;
  mcap::Reader reader(file);
  reader.read_messages([&](const mcap::Channel& c, const mcap::MessageView& m) {
    if (c.topic != "oscar/cue/" + kernel + "/out") return;
    EXPECT_EQ(c.metadata.at("kernel"), kernel);
    EXPECT_EQ(c.metadata.at("channel"), "out");
    EXPECT_EQ(c.message_encoding, "cdr");
    const std::vector<std::uint8_t> bytes(m.data.begin(), m.data.end());
    const auto cue = std::static_pointer_cast<T>(cue_type_info<T>().deserialize(bytes));
    EXPECT_TRUE(same_payload(*cue)) << kernel << " seq " << cue->header().seq();
    EXPECT_EQ(cue->header().source(), kernel + "/out");
    EXPECT_EQ(m.sequence, cue->header().seq());
    EXPECT_EQ(m.publish_time, cue->header().stamps().at(0));
    EXPECT_GE(m.log_time, m.publish_time) << "received after it was generated";
    // The bytes as published: the wire adds at most 3 zero bytes to reach a multiple of 4.
    const auto encoded = cue_type_info<T>().serialize(cue.get());
    ASSERT_GE(bytes.size(), encoded.size());
    EXPECT_LE(bytes.size() - encoded.size(), 3u);
    EXPECT_TRUE(std::equal(encoded.begin(), encoded.end(), bytes.begin()));
    EXPECT_TRUE(
        std::all_of(bytes.begin() + encoded.size(), bytes.end(), [](auto x) { return x == 0; }));
    seqs.push_back(cue->header().seq());
  });
  return seqs;
}

// Waits until the recorder subscribed to every kernel's output, then starts the kernels.
void activate_when_recorded(Process& rec, const std::vector<std::string>& kernels) {
  ASSERT_TRUE(eventually([&] {
    const auto out = rec.output();
    for (const auto& k : kernels) {
      if (out.find("oscar/cue/" + k + "/out") == std::string::npos) return false;
    }
    return true;
  })) << rec.output();
  std::this_thread::sleep_for(1s);  // the sources' writers match the recorder's readers
  DdsParticipant participant(test::test_domain(), "record_test");
  ConfigClient client(participant, "coordinator");  // only it may activate
  for (const auto& k : kernels) {
    const auto reply = client.send(k, CMD_ACTIVATE, {k, "continuous:20ms"});
    ASSERT_TRUE(reply.ok()) << k << ": " << reply.error();
  }
}

std::vector<std::uint64_t> one_to(std::uint64_t n) {
  std::vector<std::uint64_t> v(n);
  for (std::uint64_t i = 0; i < n; ++i) v[i] = i + 1;
  return v;
}

TEST(Record, HoldsEveryPublishedCueOfTheThreeSeedTypesInOrderWithItsBytes) {
  const auto file = test::temp_path("record_all.mcap");
  constexpr int kCount = 60;
  auto b = source("rb", "Bool", kCount, "deactivated");
  auto l = source("rl", "LineSeg3DSeq", kCount, "deactivated");
  auto g = source("rg", "GvImage", kCount, "deactivated");
  auto rec = recorder(file, {"--all", "--compression", "lz4"});
  activate_when_recorded(*rec, {"rb", "rl", "rg"});
  std::this_thread::sleep_for(kCount * 20ms + 1500ms);
  kill(rec->pid(), SIGINT);
  ASSERT_EQ(rec->wait(10s), 0) << rec->output();
  EXPECT_THAT(rec->output(), HasSubstr("received 180, written 180, dropped 0"));
  EXPECT_EQ(check_topic<Bool>(file, "rb"), one_to(kCount));
  EXPECT_EQ(check_topic<LineSeg3DSeq>(file, "rl"), one_to(kCount));
  EXPECT_EQ(check_topic<GvImage>(file, "rg"), one_to(kCount));
  const auto info = mcap::Reader(file).info();
  EXPECT_TRUE(info.from_summary);
  EXPECT_EQ(info.schemas.size(), 3u);
  EXPECT_EQ(info.statistics.message_count, 180u);
  EXPECT_EQ(info.compressions, std::set<std::string>{"lz4"});
}

TEST(Record, AKilledRecorderLeavesAFileReadableUpToItsLastChunk) {
  const auto file = test::temp_path("record_killed.mcap");
  auto g = source("kg", "GvImage", 0, "continuous:20ms");
  auto rec = recorder(file, {"kg/out"});
  ASSERT_TRUE(eventually([&] { return rec->output().find("kg/out") != std::string::npos; }));
  std::this_thread::sleep_for(3s);
  kill(rec->pid(), SIGKILL);
  rec->wait(5s);
  std::uint64_t seen = 0, last_seq = 0;
  mcap::Reader reader(file);
  EXPECT_FALSE(reader.has_summary());
  const auto scan = reader.read_messages([&](const mcap::Channel&, const mcap::MessageView& m) {
    EXPECT_GT(m.sequence, last_seq) << "in order";
    last_seq = m.sequence;
    ++seen;
  });
  EXPECT_GT(seen, 50u) << "~3 s at 50 Hz, less the open chunk";
  Process info({test::bin("oscar-info"), file}, test::temp_path("info.log"));
  ASSERT_EQ(info.wait(10s), 0) << info.output();
  EXPECT_THAT(info.output(), HasSubstr("summary:     none (no footer"));
  EXPECT_THAT(info.output(), HasSubstr("messages:    " + std::to_string(seen) + " in " +
                                       std::to_string(scan.chunks) + " chunks"));
  EXPECT_THAT(info.output(), HasSubstr("oscar/cue/kg/out  oscar::GvImage"));
}

TEST(Record, SplitsBySizeIntoCompleteFilesThatTogetherHoldEveryCue) {
  const auto file = test::temp_path("record_split.mcap");
  constexpr int kCount = 40;  // 40 images of 432 KiB: ~17 MiB uncompressed
  auto g = source("sg", "GvImage", kCount, "deactivated");
  auto rec = recorder(file, {"sg/out", "--compression", "none", "--split-size", "4M"});
  activate_when_recorded(*rec, {"sg"});
  std::this_thread::sleep_for(kCount * 20ms + 1500ms);
  kill(rec->pid(), SIGTERM);
  ASSERT_EQ(rec->wait(10s), 0) << rec->output();
  std::vector<std::uint64_t> seqs;
  int files = 0;
  const std::filesystem::path p(file);
  for (;; ++files) {
    const auto part = (p.parent_path() / (p.stem().string() + "_" + (files < 10 ? "00" : "0") +
                                          std::to_string(files) + p.extension().string()))
                          .string();
    if (!std::filesystem::exists(part)) break;
    EXPECT_THAT(rec->output(), HasSubstr("wrote " + part));
    mcap::Reader r(part);
    EXPECT_TRUE(r.has_summary()) << part;
    EXPECT_LT(std::filesystem::file_size(part), 6u << 20) << "4 MiB and one chunk at most";
    const auto more = check_topic<GvImage>(part, "sg");
    seqs.insert(seqs.end(), more.begin(), more.end());
  }
  EXPECT_GE(files, 4);
  EXPECT_EQ(seqs, one_to(kCount));
}

// (payload bytes, publish time, sequence) of every message per topic, in file order.
using Recorded =
    std::map<std::string,
             std::vector<std::tuple<std::vector<std::uint8_t>, std::uint64_t, std::uint32_t>>>;
Recorded messages_of(const std::string& file, std::map<std::string, std::uint64_t>* span = {}) {
  Recorded r;
  std::map<std::string, std::pair<std::uint64_t, std::uint64_t>> times;
  mcap::Reader(file).read_messages([&](const mcap::Channel& c, const mcap::MessageView& m) {
    r[c.topic].emplace_back(std::vector<std::uint8_t>(m.data.begin(), m.data.end()), m.publish_time,
                            m.sequence);
    auto& t = times.try_emplace(c.topic, m.log_time, m.log_time).first->second;
    t.second = m.log_time;
  });
  if (span) {
    for (const auto& [topic, t] : times) (*span)[topic] = t.second - t.first;
  }
  return r;
}

TEST(Replay, DeliversTheRecordedBytesAndHeadersInOrderWithTheOriginalTiming) {
  const auto original = test::temp_path("replay_original.mcap");
  const auto replayed = test::temp_path("replay_replayed.mcap");
  constexpr int kCount = 30;
  {
    auto b = source("pb", "Bool", kCount, "deactivated");
    auto l = source("pl", "LineSeg3DSeq", kCount, "deactivated");
    auto g = source("pg", "GvImage", kCount, "deactivated");
    auto rec = recorder(original, {"--all"});
    activate_when_recorded(*rec, {"pb", "pl", "pg"});
    std::this_thread::sleep_for(kCount * 20ms + 1500ms);
    kill(rec->pid(), SIGINT);
    ASSERT_EQ(rec->wait(10s), 0) << rec->output();
  }  // the sources are gone: what the fresh consumer gets comes from the replay
  auto consumer = recorder(replayed, {"--all"});
  std::this_thread::sleep_for(300ms);
  Process replay(
      {test::bin("oscar-replay"), original, "--domain", std::to_string(test::test_domain())},
      test::temp_path("replay.log"));
  ASSERT_EQ(replay.wait(30s), 0) << replay.output();
  EXPECT_THAT(replay.output(), HasSubstr("published 90 messages on 3 topics"));
  EXPECT_THAT(replay.output(),
              ContainsRegex("publishing began late by p50 [0-9]+ us, p99 [0-9]+ us, max [0-9]+ us"))
      << "its own account of its timing";
  std::this_thread::sleep_for(500ms);
  kill(consumer->pid(), SIGINT);
  ASSERT_EQ(consumer->wait(10s), 0) << consumer->output();
  std::map<std::string, std::uint64_t> span_original, span_replayed;
  const auto a = messages_of(original, &span_original);
  const auto b = messages_of(replayed, &span_replayed);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_TRUE(a == b) << "same bytes, publish times (the cue headers) and order per topic";
  // Paced as recorded, not blasted out at once: never faster than the original (a little
  // rounding aside); slower only by what a loaded or sanitized run costs. Timing accuracy itself
  // is measured by `oscar bench replay`, not asserted here.
  for (const auto& [topic, ns] : span_original) {
    EXPECT_GE(span_replayed[topic] / 1e6, 0.9 * ns / 1e6 - 20) << topic << " in ms";
    EXPECT_LE(span_replayed[topic] / 1e6, 3.0 * ns / 1e6 + 500) << topic << " in ms";
  }
}

TEST(Replay, LoopsTheRecordingInOrderUntilStopped) {
  // Five Bools 20 ms apart, written directly: one pass takes 80 ms.
  const auto file = test::temp_path("replay_loop.mcap");
  {
    mcap::Writer w(file, {});
    const auto channel = w.add_channel(0, "oscar/cue/lp/out", "cdr", {{"type", "oscar::Bool"}});
    Bool b;
    const std::uint64_t t0 = 1'000'000'000'000;
    for (std::uint32_t seq = 1; seq <= 5; ++seq) {
      b.header().seq(seq);
      b.header().stamps({t0 + seq * 20'000'000ull});
      const auto bytes = cue_type_info<Bool>().serialize(&b);
      mcap::MessageView m;
      m.channel_id = channel;
      m.sequence = seq;
      m.log_time = m.publish_time = t0 + seq * 20'000'000ull;
      m.data = bytes;
      w.write(m);
    }
    w.close();
  }
  const auto replayed = test::temp_path("replay_loop_replayed.mcap");
  auto consumer = recorder(replayed, {"--all"});
  std::this_thread::sleep_for(300ms);
  Process replay(
      {test::bin("oscar-replay"), file, "--loop", "--domain", std::to_string(test::test_domain())},
      test::temp_path("replay_loop.log"));
  // Its writers exist once it says what it replays; then it waits up to 2 s for its reader
  // (longer than a pass takes under a sanitizer, with a participant per topic).
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (replay.output().find("replaying oscar/cue/lp/out") == std::string::npos &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(50ms);
  }
  std::this_thread::sleep_for(3s);
  kill(replay.pid(), SIGINT);
  ASSERT_EQ(replay.wait(10s), 0) << replay.output();
  std::this_thread::sleep_for(300ms);
  kill(consumer->pid(), SIGINT);
  ASSERT_EQ(consumer->wait(10s), 0) << consumer->output();
  const auto got = messages_of(replayed)["oscar/cue/lp/out"];
  ASSERT_GE(got.size(), 15u) << "at least three passes";
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(std::get<2>(got[i]), i % 5 + 1) << "message " << i << ": passes in file order";
  }
  EXPECT_LE(got.size(), 5u * 50) << "paced (80 ms a pass), not blasted out";
}

TEST(Replay, OntoATopicOfAnotherTypeIsAClearError) {
  const auto file = test::temp_path("replay_mismatch.mcap");
  {
    auto g = source("xg", "GvImage", 5, "deactivated");
    auto rec = recorder(file, {"xg/out"});
    activate_when_recorded(*rec, {"xg"});
    std::this_thread::sleep_for(1s);
    kill(rec->pid(), SIGINT);
    ASSERT_EQ(rec->wait(10s), 0) << rec->output();
  }
  auto b = source("xb", "Bool", 0, "continuous:50ms");
  std::this_thread::sleep_for(500ms);
  Process replay({test::bin("oscar-replay"), file, "--remap", "xg/out:=xb/out", "--domain",
                  std::to_string(test::test_domain())},
                 test::temp_path("replay_mismatch.log"));
  EXPECT_EQ(replay.wait(20s), 1);
  EXPECT_THAT(replay.output(), HasSubstr("oscar replay: topic 'oscar/cue/xb/out' carries "
                                         "oscar::Bool in the running system, not oscar::GvImage"));
}

}  // namespace
}  // namespace oscar
