// Record -> replay round trip through a booted system (issue 4): three bench_source modules
// publish known sequences of the three seed types; oscar record holds exactly what was
// published; replaying the file into a fresh consumer delivers the same bytes and headers in the
// same order.
#include <csignal>
#include <filesystem>
#include <mutex>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/cue_header_cdr.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/mcap/reader.hpp"
#include "oscar/testing/eventually.hpp"
#include "raw_tap.hpp"  // tools/inspect

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::Process;

constexpr int kCount = 30;

struct Message {
  std::vector<std::uint8_t> bytes;
  std::uint64_t seq;
};

// The header fields a consumer sees, decoded with the compiled type.
std::string header_text(const std::string& topic, const std::vector<std::uint8_t>& bytes) {
  const auto& info = topic.find("/img/") != std::string::npos     ? cue_type_info<GvImage>()
                     : topic.find("/lines/") != std::string::npos ? cue_type_info<LineSeg3DSeq>()
                                                                  : cue_type_info<Bool>();
  const auto cue = info.deserialize(bytes);
  const auto h = info.header.read(cue.get());
  return fmt::format("{} #{} @ {}", h.source(), h.seq(), fmt::join(h.stamps(), " "));
}

TEST(RoundTrip, RecordingABootedSystemAndReplayingItDeliversTheSameBytesHeadersAndOrder) {
  const auto file = test::temp_path("roundtrip") + ".mcap";
  const auto domain = std::to_string(test::test_domain());
  BootedSystem system("roundtrip", fmt::format(R"(
system: roundtrip
lease: 1s
modules:
  - name: flag
    kernels: [ {{ type: bench_source, name: flag, params: {{ type: Bool, count: {0} }} }} ]
    mode: deactivated
  - name: lines
    kernels: [ {{ type: bench_source, name: lines, params: {{ type: LineSeg3DSeq, count: {0} }} }} ]
    mode: deactivated
  - name: img
    kernels: [ {{ type: bench_source, name: img, params: {{ type: GvImage, count: {0} }} }} ]
    mode: deactivated
)",
                                               kCount));
  system.running();
  Process rec({test::bin("oscar-record"), "--all", "-o", file, "--domain", domain},
              test::temp_path("roundtrip_record") + ".log");
  ASSERT_TRUE(eventually(
      [&] {
        const auto out = rec.output();
        return out.find("oscar/cue/flag/out") != std::string::npos &&
               out.find("oscar/cue/lines/out") != std::string::npos &&
               out.find("oscar/cue/img/out") != std::string::npos;
      },
      15s, 20ms))
      << rec.output();
  std::this_thread::sleep_for(1s);
  for (const auto* k : {"flag", "lines", "img"}) {
    const auto reply = system.configure(k, CMD_ACTIVATE, {k, "continuous:20ms"});
    ASSERT_TRUE(reply.ok()) << k << ": " << reply.error();
  }
  std::this_thread::sleep_for(kCount * 20ms + 2s);
  kill(rec.pid(), SIGINT);
  ASSERT_EQ(rec.wait(20s), 0) << rec.output();
  EXPECT_THAT(rec.output(), ::testing::HasSubstr("received 90, written 90, dropped 0"));
  ASSERT_EQ(system.shut_down(), 0);  // nothing else publishes on these topics now

  // The recording: per topic seq 1..kCount in order.
  std::map<std::string, std::vector<Message>> recorded;
  mcap::Reader(file).read_messages([&](const mcap::Channel& c, const mcap::MessageView& m) {
    recorded[c.topic].push_back({{m.data.begin(), m.data.end()}, m.sequence});
  });
  ASSERT_EQ(recorded.size(), 3u);
  for (const auto& [topic, messages] : recorded) {
    ASSERT_EQ(messages.size(), static_cast<std::size_t>(kCount)) << topic;
    for (int i = 0; i < kCount; ++i) EXPECT_EQ(messages[i].seq, i + 1u) << topic;
  }

  // A fresh consumer hears the replay.
  DdsParticipant participant(test::test_domain(), "roundtrip_consumer");
  std::mutex mutex;
  std::map<std::string, std::vector<Message>> replayed;
  inspect::RawTap tap(participant, [&](const std::string& topic, auto bytes, auto) {
    const auto h = read_cue_header(bytes);
    std::lock_guard lock(mutex);
    replayed[topic].push_back({std::move(bytes), h ? h->seq() : 0});
  });
  Process replay({test::bin("oscar-replay"), file, "--domain", domain},
                 test::temp_path("roundtrip_replay") + ".log");
  ASSERT_TRUE(eventually(
      [&] {
        std::size_t n = 0;
        for (const auto& [topic, m] : recorded) n += tap.subscribe(topic).empty() ? 0 : 1;
        return n == recorded.size();
      },
      10s, 20ms))
      << replay.output();
  ASSERT_EQ(replay.wait(60s), 0) << replay.output();
  std::this_thread::sleep_for(500ms);
  std::lock_guard lock(mutex);
  for (const auto& [topic, messages] : recorded) {
    const auto& got = replayed[topic];
    ASSERT_EQ(got.size(), messages.size()) << topic;
    for (std::size_t i = 0; i < messages.size(); ++i) {
      EXPECT_EQ(got[i].seq, messages[i].seq) << topic << " #" << i;
      EXPECT_TRUE(got[i].bytes == messages[i].bytes) << topic << " #" << i << ": other bytes";
      EXPECT_EQ(header_text(topic, got[i].bytes), header_text(topic, messages[i].bytes));
    }
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace oscar
