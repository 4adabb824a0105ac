// The zero-copy path (docs/zero_copy.md): plain types, the path choice with its reasons, and
// cues across processes through a RouDi of the test's own. Every test process runs in a private
// mount namespace with its own /dev/shm and /tmp (iceoryx 2.0's names there are fixed:
// /dev/shm/iceoryx_mgmt, /tmp/roudi), so tests run in parallel and leave no files behind.
#include <signal.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <iceoryx_hoofs/error_handling/error_handling.hpp>

#include "oscar/cue_types.hpp"
#include "private_tmp.hpp"
#include "proc.hpp"
#include "process.hpp"
#include "zero_copy/chunk_identity.hpp"
#include "zero_copy/cue_path.hpp"
#include "zero_copy/mempools.hpp"
#include "zero_copy/plain_cue.hpp"
#include "zero_copy/roudi.hpp"

namespace oscar::zero_copy {
namespace {

template <class Condition>
bool eventually(Condition condition, std::chrono::seconds timeout = std::chrono::seconds(60)) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

std::string peer() { return oscar::test::bin("oscar-zero-copy-peer"); }

// RouDi in the private namespace, with mempools of `image_chunks` image-sized chunks and
// plenty of the others.
std::unique_ptr<oscar::test::Process> start_roudi(std::uint32_t image_chunks) {
  std::ofstream("/tmp/roudi.toml") << roudi_config(
      {mempool_for<oscar::PlainBool>(200), mempool_for<oscar::PlainLineSeg3DSeq>(200),
       mempool_for<oscar::PlainGvImage>(image_chunks)});
  auto roudi = std::make_unique<oscar::test::Process>(
      std::vector<std::string>{"/usr/bin/iox-roudi", "-c", "/tmp/roudi.toml", "-l", "info"},
      "/tmp/roudi.log");
  if (!eventually([] { return roudi_running(); }) || roudi->wait(std::chrono::milliseconds(0)))
    ADD_FAILURE() << "iox-roudi did not come up: " << roudi->output();
  return roudi;
}

struct Peer {
  explicit Peer(std::vector<std::string> args, const std::string& name)
      : process(
            [&] {
              args.insert(args.begin(), peer());
              return args;
            }(),
            "/tmp/" + name + ".log") {}
  // Lines of the peer's output that start with `what` ("published", "received").
  std::vector<std::string> lines(const std::string& what) const {
    std::vector<std::string> out;
    std::istringstream in(process.output());
    for (std::string line; std::getline(in, line);)
      if (line.rfind(what + " ", 0) == 0) out.push_back(line);
    return out;
  }
  bool printed(const std::string& text) const {
    return process.output().find(text) != std::string::npos;
  }
  oscar::test::Process process;
};

// seq -> "segment=S offset=O": where the cue lay in shared memory (a chunk's sequence number is
// set when it is published, so the producer cannot print it beforehand).
std::map<std::string, std::string> by_seq(const std::vector<std::string>& lines) {
  static const std::regex pattern(R"(^\w+ seq=(\d+) (segment=\d+ offset=\d+) .*$)");
  std::map<std::string, std::string> out;
  for (const auto& line : lines) {
    std::smatch m;
    if (std::regex_match(line, m, pattern)) out[m[1]] = m[2];
  }
  return out;
}

class ZeroCopy : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!oscar::test::kNoPrivateTmp.empty())
      GTEST_SKIP() << "needs a private mount namespace (root): " << oscar::test::kNoPrivateTmp;
    ASSERT_TRUE(std::filesystem::exists(peer())) << peer() << " is missing (OSCAR_BUILD_DIR?)";
  }
};

TEST(PlainCues, FastDdsCallsThePlainTypesPlainAndTheSequenceTypesNot) {
  EXPECT_TRUE(PlainCueTraits<oscar::PlainBool>::PubSubType().is_plain());
  EXPECT_TRUE(PlainCueTraits<oscar::PlainLineSeg3DSeq>::PubSubType().is_plain());
  EXPECT_TRUE(PlainCueTraits<oscar::PlainGvImage>::PubSubType().is_plain());
  EXPECT_FALSE(oscar::GvImagePubSubType().is_plain());
  EXPECT_FALSE(oscar::LineSeg3DSeqPubSubType().is_plain());
  EXPECT_FALSE(oscar::BoolPubSubType().is_plain());  // its header's stamps and source
}

TEST(PlainCues, APlainImageHoldsTheSeedBenchmarksImageInItself) {
  oscar::PlainGvImage image;
  const auto* begin = reinterpret_cast<const char*>(&image);
  const auto* pixels = reinterpret_cast<const char*>(image.image().data());
  EXPECT_GE(pixels, begin);
  EXPECT_LE(pixels + 442368, begin + sizeof image);
}

// A copy is told from a chunk: an address in none of iceoryx's segments has no identity (iceoryx
// itself calls it segment 0, "a regular pointer").
TEST(ChunkIdentity, MemoryOutsideSharedMemoryIsNoChunk) {
  const auto heap = std::make_shared<oscar::PlainGvImage>();
  const oscar::PlainBool stack;
  EXPECT_FALSE(identify_chunk(heap.get()));
  EXPECT_FALSE(identify_chunk(&stack));
  EXPECT_FALSE(identify_chunk(nullptr));
}

TEST(Mempools, AChunkHoldsTheCueAndIceoryxsHeaderInMultiplesOfEight) {
  for (const auto& pool : plain_cue_mempools(3)) {
    EXPECT_EQ(pool.count, 3u);
    EXPECT_EQ(pool.chunk_bytes % 8, 0u);
  }
  const auto image = mempool_for<oscar::PlainGvImage>(1).chunk_bytes;
  EXPECT_GE(image, sizeof(oscar::PlainGvImage) + 32);  // iceoryx's chunk header: 32 bytes or more
  EXPECT_LT(image, sizeof(oscar::PlainGvImage) + 256);
  EXPECT_THROW(chunk_bytes_for(std::size_t{1} << 33, 8), std::invalid_argument);
}

TEST(Mempools, TheConfigListsPoolsAscendingWithEqualSizesMerged) {
  EXPECT_EQ(roudi_config({{1024, 2}, {128, 5}, {1024, 3}}),
            "[general]\nversion = 1\n\n[[segment]]\n"
            "\n[[segment.mempool]]\nsize = 128\ncount = 5\n"
            "\n[[segment.mempool]]\nsize = 1024\ncount = 5\n");
  try {
    roudi_config({{128, 0}});
    FAIL() << "a pool without chunks was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at least one chunk"), std::string::npos) << e.what();
  }
  EXPECT_THROW(roudi_config({}), std::invalid_argument);
}

TEST(CuePath, AnUnplainTypeGoesSerializedWithOneLineSayingWhy) {
  register_standard_cue_types();
  std::ostringstream log;
  auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>(
      "zc", std::make_shared<spdlog::sinks::ostream_sink_st>(log)));
  const auto* image = find_cue_type("oscar::GvImage");
  ASSERT_NE(image, nullptr);
  const auto choice = choose_cue_path(connection_facts("cam/image", *image, true));
  spdlog::set_default_logger(previous);
  const auto lines = log.str();
  EXPECT_EQ(choice.path, CuePath::kSerialized);
  EXPECT_NE(choice.reason.find("oscar::GvImage is not plain"), std::string::npos) << choice.reason;
  EXPECT_NE(lines.find("cues of cam/image go serialized, not zero-copy: cue type "
                       "oscar::GvImage is not plain"),
            std::string::npos)
      << lines;
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 1) << lines;
}

TEST(CuePath, EachFactRulesZeroCopyOutWithItsOwnReason) {
  const ConnectionFacts all{"cam/image", "oscar::PlainGvImage", true, true, true};
  EXPECT_EQ(choose_cue_path(all).path, CuePath::kZeroCopy);
  EXPECT_TRUE(choose_cue_path(all).reason.empty());
  auto remote = all;
  remote.producer_on_this_host = false;
  EXPECT_NE(choose_cue_path(remote).reason.find("another host"), std::string::npos);
  auto no_roudi = all;
  no_roudi.roudi_running = false;
  EXPECT_NE(choose_cue_path(no_roudi).reason.find("no RouDi"), std::string::npos);
  EXPECT_EQ(choose_cue_path(no_roudi).path, CuePath::kSerialized);
}

// iceoryx 2.0 aborts on a severe error of its own, e.g. a port request that a RouDi killed
// meanwhile leaves unanswered. With end_process_on_iceoryx_error the process says which error and
// ends with the exit code asked for (a module's: the registry starts it again); a moderate error
// is said and the process goes on.
TEST(IceoryxErrors, ASevereOneEndsTheProcessWithTheCodeAskedForAModerateOneGoesOn) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto install = [] {
    end_process_on_iceoryx_error(7, [](const std::string& what, bool ending) {
      std::fprintf(stderr, "%s: %s\n", ending ? "ending" : "going on", what.c_str());
    });
  };
  EXPECT_EXIT(
      {
        install();
        iox::errorHandler(iox::Error::kPOSH__RUNTIME_ROUDI_REQUEST_PUBLISHER_INVALID_RESPONSE,
                          nullptr, iox::ErrorLevel::SEVERE);
        std::abort();  // what iceoryx's own handler does
      },
      testing::ExitedWithCode(7),
      "ending: iceoryx reports POSH__RUNTIME_ROUDI_REQUEST_PUBLISHER_INVALID_RESPONSE, a severe "
      "error it cannot go on from");
  EXPECT_EXIT(
      {
        install();
        iox::errorHandler(iox::Error::kPOPO__CHUNK_LOCKING_ERROR, nullptr,
                          iox::ErrorLevel::MODERATE);
        std::fprintf(stderr, "went on\n");
        std::exit(0);
      },
      testing::ExitedWithCode(0),
      "going on: iceoryx reports POPO__CHUNK_LOCKING_ERROR and goes on\nwent on");
}

TEST_F(ZeroCopy, WithoutRouDiAPeerSaysSoInsteadOfWaiting) {
  EXPECT_FALSE(roudi_running());
  Peer sub({"sub", "PlainBool", "t", "1", "1"}, "sub");
  ASSERT_EQ(sub.process.wait(std::chrono::seconds(30)), 5) << sub.process.output();
  EXPECT_TRUE(sub.printed("no zero-copy: no RouDi runs on this host")) << sub.process.output();
}

TEST_F(ZeroCopy, WithoutIoxRoudiInstalledAPeerNamesThePackage) {
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", "/nonexistent", 1);  // the peer's search finds no iox-roudi
  Peer sub({"sub", "PlainBool", "t", "1", "1"}, "sub");
  ::setenv("PATH", path.c_str(), 1);
  ASSERT_EQ(sub.process.wait(std::chrono::seconds(30)), 5) << sub.process.output();
  EXPECT_TRUE(sub.printed("no zero-copy: iox-roudi is not installed (Debian package iceoryx)"))
      << sub.process.output();
}

// The consumer's cue is the producer's chunk: the same segment, offset and chunk sequence number
// in both processes, and its content as written.
class ZeroCopyType : public ZeroCopy, public ::testing::WithParamInterface<std::string> {};

TEST_P(ZeroCopyType, TheConsumerReadsTheProducersChunkInPlace) {
  auto roudi = start_roudi(40);
  Peer sub({"sub", GetParam(), "bench/cue", "20", "16"}, "sub");
  ASSERT_TRUE(eventually([&] { return sub.printed("subscribed"); })) << sub.process.output();
  Peer pub({"pub", GetParam(), "bench/cue", "20", "10", "0", "0", "1"}, "pub");
  ASSERT_EQ(sub.process.wait(std::chrono::seconds(60)), 0) << sub.process.output();
  ASSERT_EQ(pub.process.wait(std::chrono::seconds(60)), 0) << pub.process.output();
  const auto published = by_seq(pub.lines("published"));
  const auto received = by_seq(sub.lines("received"));
  ASSERT_EQ(received.size(), 20u) << sub.process.output();
  for (const auto& [seq, where] : received) {
    ASSERT_TRUE(published.count(seq)) << seq;
    EXPECT_EQ(where, published.at(seq)) << "cue " << seq << " is not the producer's chunk";
  }
  for (const auto& line : sub.lines("received")) EXPECT_NE(line.find(" ok=1"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(BenchTypes, ZeroCopyType,
                         ::testing::Values("PlainBool", "PlainLineSeg3DSeq", "PlainGvImage"));

TEST_F(ZeroCopy, ARingBufferHoldsTheChunksAndEvictionGivesThemBack) {
  // 6 image chunks and a ring of 4: without eviction giving chunks back the producer would run
  // out after a few cues.
  auto roudi = start_roudi(6);
  Peer ring({"ring", "PlainGvImage", "cam/image", "40", "4"}, "ring");
  ASSERT_TRUE(eventually([&] { return ring.printed("subscribed"); })) << ring.process.output();
  Peer pub({"pub", "PlainGvImage", "cam/image", "40", "10", "0", "0", "1"}, "pub");
  ASSERT_EQ(pub.process.wait(std::chrono::seconds(60)), 0) << pub.process.output();
  ASSERT_EQ(ring.process.wait(std::chrono::seconds(60)), 0) << ring.process.output();
  const auto published = by_seq(pub.lines("published"));
  const auto ringed = by_seq(ring.lines("ringed"));
  EXPECT_EQ(ringed.size(), 40u);
  for (const auto& [seq, where] : ringed) EXPECT_EQ(where, published.at(seq)) << seq;
  for (const auto& line : ring.lines("ringed")) EXPECT_NE(line.find(" ok=1"), std::string::npos);
  EXPECT_TRUE(ring.printed("after the subscriber: 4 cues held, readable=1"))
      << ring.process.output();
  EXPECT_TRUE(ring.printed("released")) << ring.process.output();
}

// RouDi frees a killed process's chunks once it stops answering (~1.5 s); its log names it.
bool roudi_removed(const oscar::test::Process& roudi, pid_t pid) {
  std::istringstream in(roudi.output());
  for (std::string line; std::getline(in, line);)
    if (line.find(fmt::format("-{} ", pid)) != std::string::npos &&
        line.find("removing") != std::string::npos)
      return true;
  return false;
}

TEST_F(ZeroCopy, AKilledProducersChunksComeBackAndTheConsumerGoesOn) {
  // 18 image chunks: the killed producer holds 7 loans (iceoryx allows 8 per publisher) and the
  // consumer 4 of its cues; a second producer could not loan 7 and publish if they never came
  // back.
  auto roudi = start_roudi(18);
  Peer sub({"sub", "PlainGvImage", "cam/image", "0", "4"}, "sub");
  ASSERT_TRUE(eventually([&] { return sub.printed("subscribed"); })) << sub.process.output();
  Peer first({"pub", "PlainGvImage", "cam/image", "5", "10", "7", "1", "1"}, "first");
  ASSERT_TRUE(eventually([&] { return first.printed("done"); })) << first.process.output();
  ASSERT_TRUE(eventually([&] { return sub.printed("received seq=5 "); })) << sub.process.output();
  ::kill(first.process.pid(), SIGKILL);
  first.process.wait(std::chrono::seconds(10));
  ASSERT_TRUE(eventually([&] { return roudi_removed(*roudi, first.process.pid()); }))
      << roudi->output();
  Peer second({"pub", "PlainGvImage", "cam/image", "30", "10", "7", "0", "101"}, "second");
  ASSERT_EQ(second.process.wait(std::chrono::seconds(60)), 0) << second.process.output();
  EXPECT_TRUE(eventually([&] { return sub.printed("received seq=130 "); })) << sub.process.output();
  EXPECT_FALSE(sub.process.wait(std::chrono::milliseconds(0))) << "the consumer ended";
  for (const auto& line : sub.lines("received"))
    EXPECT_NE(line.find("ok=1"), std::string::npos) << line;
}

TEST_F(ZeroCopy, AKilledConsumersChunksComeBackAndTheProducerGoesOn) {
  // 40 image chunks: the killed consumer holds 16 and had up to 16 queued; a second consumer
  // holding 16 more would leave the producer none if they never came back.
  auto roudi = start_roudi(40);
  Peer first({"sub", "PlainGvImage", "cam/image", "0", "16"}, "first");
  ASSERT_TRUE(eventually([&] { return first.printed("subscribed"); })) << first.process.output();
  Peer pub({"pub", "PlainGvImage", "cam/image", "100000", "10", "0", "0", "1"}, "pub");
  ASSERT_TRUE(eventually([&] { return first.lines("received").size() >= 30; }))
      << first.process.output();
  ::kill(first.process.pid(), SIGKILL);
  first.process.wait(std::chrono::seconds(10));
  ASSERT_TRUE(eventually([&] { return roudi_removed(*roudi, first.process.pid()); }))
      << roudi->output();
  Peer second({"sub", "PlainGvImage", "cam/image", "80", "16"}, "second");
  ASSERT_EQ(second.process.wait(std::chrono::seconds(60)), 0) << second.process.output();
  EXPECT_FALSE(pub.process.wait(std::chrono::milliseconds(0))) << pub.process.output();
  EXPECT_FALSE(pub.printed("loan failed")) << pub.process.output();
  for (const auto& line : second.lines("received"))
    EXPECT_NE(line.find("ok=1"), std::string::npos) << line;
}

// iceoryx 2.0 waits for good for RouDi's answer to a port request, and a RouDi that hung (here:
// stopped) and was killed and replaced by its monitor never answers. The process that asked ends,
// saying so, so that its registry starts it again on the new RouDi.
class ZeroCopyPortRequest : public ZeroCopy, public ::testing::WithParamInterface<std::string> {};

TEST_P(ZeroCopyPortRequest, EndsTheProcessWhenTheRouDiAskedGoesAwayWithoutAnswering) {
  const bool publisher = GetParam() == "publisher";
  auto roudi = start_roudi(8);
  std::filesystem::remove("/tmp/go");
  ::setenv("OSCAR_PEER_PORTS_AFTER", "/tmp/go", 1);
  Peer asking(publisher
                  ? std::vector<std::string>{"pub", "PlainBool", "flag", "1", "10", "0", "0", "1"}
                  : std::vector<std::string>{"sub", "PlainBool", "flag", "1", "1"},
              "asking");
  ::unsetenv("OSCAR_PEER_PORTS_AFTER");
  ASSERT_TRUE(eventually([&] { return asking.printed("joined"); })) << asking.process.output();
  ::kill(roudi->pid(), SIGSTOP);
  // Asked before RouDi has really stopped, it would still answer.
  ASSERT_TRUE(eventually([&] { return oscar::test::stopped(roudi->pid()); }));
  std::ofstream("/tmp/go");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(asking.process.wait(std::chrono::milliseconds(0)))
      << "it waits for the stopped RouDi's answer: " << asking.process.output();
  ::kill(roudi->pid(), SIGKILL);
  roudi->wait(std::chrono::seconds(10));
  roudi = start_roudi(8);
  EXPECT_EQ(asking.process.wait(std::chrono::seconds(10)), 1) << asking.process.output();
  // Gone ("takes no message") or replaced ("is another socket"), whichever it sees first.
  EXPECT_TRUE(asking.printed(fmt::format(
      "the RouDi this process asked for a {} port went away before it answered (/tmp/roudi ",
      GetParam())))
      << asking.process.output();
  EXPECT_TRUE(asking.printed("the process ends with exit code 1")) << asking.process.output();
}

INSTANTIATE_TEST_SUITE_P(Port, ZeroCopyPortRequest, ::testing::Values("publisher", "subscriber"),
                         [](const ::testing::TestParamInfo<std::string>& port) {
                           return port.param;
                         });

}  // namespace
}  // namespace oscar::zero_copy
