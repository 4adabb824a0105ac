// Samples sent under OSCAR's type names with another layout (framework/src/dds/README.md,
// "Malformed samples"): a participant of the test publishes crafted bytes with a raw type
// support, as a foreign or broken sender would. No reader may crash, the samples are dropped,
// counted and logged, and a reader allocates nothing for counts its bytes cannot hold.
#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/malformed_samples.hpp"
#include "oscar/output.hpp"
#include "oscar/raw_cdr_type.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"

#include <oscar/configPubSubTypes.h>

namespace oscar {
namespace {
using namespace std::chrono_literals;
namespace dds = eprosima::fastdds::dds;

// Publishes bytes as they are under a type name (RawCdrType, as oscar replay does).
class ForgedWriter {
 public:
  ForgedWriter(DdsParticipant& p, const std::string& topic, const std::string& type,
               const dds::DataWriterQos& qos)
      : participant_(p), type_(type) {
    writer_ = p.publisher().create_datawriter(&p.topic(topic, new RawCdrType(type)), qos);
    if (!writer_) throw std::runtime_error("cannot create a writer for " + topic);
  }
  ~ForgedWriter() { participant_.publisher().delete_datawriter(writer_); }
  int matched() const {
    dds::PublicationMatchedStatus s;
    writer_->get_publication_matched_status(s);
    return s.current_count;
  }
  void write(std::vector<std::uint8_t> bytes) {
    RawCue cue{.type = type_, .cdr = std::move(bytes), .cue_header = {}};
    ASSERT_TRUE(writer_->write(&cue));
  }

 private:
  DdsParticipant& participant_;
  std::string type_;
  dds::DataWriter* writer_ = nullptr;
};

std::vector<std::uint8_t> bool_bytes(std::uint64_t seq, std::uint8_t value_byte) {
  Bool b;
  b.header().stamps({1});
  b.header().source("forger/out");
  b.header().seq(seq);
  b.value(true);
  auto bytes = cue_type_info<Bool>().serialize(&b);
  bytes.back() = value_byte;  // the value is the last byte
  return bytes;
}

std::vector<std::uint8_t> serialized(ModuleState s) {
  ModuleStatePubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&s)());
  type.serialize(&s, &payload);
  return {payload.data, payload.data + payload.length};
}

// /proc/self/status's peak resident size (VmHWM) in KiB.
long peak_rss_kib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.starts_with("VmHWM:")) return std::stol(line.substr(6));
  }
  return -1;
}

// Lets VmHWM start again from the current resident size (Linux's clear_refs, value 5).
bool reset_peak_rss() { return static_cast<bool>(std::ofstream("/proc/self/clear_refs") << "5"); }

TEST(MalformedSamples, AModuleDropsABoolWhoseValueByteIs2AndTakesTheNextCues) {
  const auto report = test::temp_path("malformed_bool_report.json");
  std::filesystem::remove(report);
  auto sink = test::run_module(
      "sink", {"-k", "bench_sink:sink", "-p", "sink.type=Bool", "-p", "sink.report=" + report, "-p",
               "sink.expect=2", "-i", "sink.in=forger/out", "-m", "single_step"});
  DdsParticipant forger(test::test_domain(), "forger");
  ForgedWriter writer(forger, topics::cue("forger/out"), "oscar::Bool",
                      qos::cue_writer(OutputOptions{}));
  ASSERT_TRUE(eventually([&] { return writer.matched() > 0; }, 15s)) << sink->output();
  writer.write(bool_bytes(1, 2));
  writer.write(bool_bytes(2, 1));
  writer.write(bool_bytes(3, 0));
  ASSERT_TRUE(eventually([&] { return std::filesystem::exists(report); }, 15s)) << sink->output();
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(report))["received"], 2);
  EXPECT_FALSE(sink->wait(0ms)) << "the module ended:\n" << sink->output();
  EXPECT_TRUE(eventually([&] {
    return sink->output().find(
               "dropped a malformed sample on oscar/cue/forger/out (oscar::Bool)") !=
           std::string::npos;
  })) << sink->output();
}

// Pids of the registries of a booted system.
std::vector<long> registries_of(const test::BootedSystem& system) {
  std::vector<long> out;
  for (const long pid : test::processes_mentioning(system.file())) {
    if (test::proc_file(pid, "cmdline").find("oscar-registry") != std::string::npos) {
      out.push_back(pid);
    }
  }
  return out;
}

TEST(MalformedSamples, TheRegistryDropsAModuleStateWithABadBooleanAndKeepsReadingStates) {
  test::BootedSystem system("malformed_state", R"(
system: malformed_state
lease: 1s
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: deactivated
)");
  system.running();
  const auto registries = registries_of(system);
  ASSERT_EQ(registries.size(), 1u) << system.boot_output();

  // `suspended` is the only byte in which these two differ.
  ModuleState state;
  state.module_name("src");
  state.host("localhost");
  auto bytes = serialized(state);
  state.suspended(true);
  const auto with_true = serialized(state);
  ASSERT_EQ(bytes.size(), with_true.size());
  const auto at = std::mismatch(bytes.begin(), bytes.end(), with_true.begin()).first;
  ASSERT_NE(at, bytes.end());
  *at = 2;

  DdsParticipant forger(system.domain(), "forger");
  const auto spec = topics::module_state();
  ForgedWriter writer(forger, spec.name, "oscar::ModuleState", spec.writer_qos);
  ASSERT_TRUE(eventually([&] { return writer.matched() > 0; }, 15s));
  writer.write(bytes);
  const auto registry_log = [&] {
    std::ifstream in(system.log_dir() + "/registry.log");
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  EXPECT_TRUE(eventually([&] {
    return registry_log().find("dropped a malformed sample on oscar/registry/module_state") !=
           std::string::npos;
  })) << registry_log();
  EXPECT_TRUE(test::alive(registries.front())) << system.boot_output();

  // The registry still reads the states modules announce.
  const auto reply = system.configure("src", CMD_ACTIVATE, {"src", "continuous:50ms"});
  ASSERT_TRUE(reply.ok()) << reply.error();
  system.wait_for(
      [](const SystemState& s) {
        const auto* m = test::entry(s, "src");
        const auto* k = m ? test::kernel_state(*m, "src") : nullptr;
        return k && k->mode() == "continuous";
      },
      15s);
  EXPECT_TRUE(test::alive(registries.front()));
}

TEST(MalformedSamples, ALineSeg3DSeqClaimingALinePerByteIsDroppedBeforeTheReaderAllocates) {
  if (!reset_peak_rss()) GTEST_SKIP() << "cannot reset VmHWM through /proc/self/clear_refs";
  const auto topic = topics::cue("forger/lines");
  DdsParticipant reader_side(test::test_domain(), "lines_reader");
  std::atomic<int> whole{0}, other{0};
  TopicReader<LineSeg3DSeq, LineSeg3DSeqPubSubType> reader(
      reader_side, topic, qos::cue_reader(OutputOptions{}, 4, Reliability::kAsProducer),
      [&](const LineSeg3DSeq& s, const auto&) { ++(s.lines().size() == 2 ? whole : other); });
  DdsParticipant forger(test::test_domain(), "forger");
  ForgedWriter writer(forger, topic, "oscar::LineSeg3DSeq", qos::cue_writer(OutputOptions{}));
  ASSERT_TRUE(eventually([&] { return writer.matched() > 0 && reader.matched() > 0; }, 15s));

  // 4 MiB of zeros after a count that claims one line (48 bytes) per byte: Fast CDR's own
  // check (a byte per element) passes it, and the reader would reserve 192 MiB before failing.
  constexpr std::uint32_t kClaimed = 4u << 20;
  LineSeg3DSeq empty;
  auto forged = cue_type_info<LineSeg3DSeq>().serialize(&empty);
  std::memcpy(forged.data() + forged.size() - 4, &kClaimed, 4);  // little endian, as written
  forged.resize(forged.size() + kClaimed);
  LineSeg3DSeq two;
  two.lines().resize(2);

  ASSERT_TRUE(reset_peak_rss());
  const long before = peak_rss_kib();
  for (int i = 0; i < 3; ++i) writer.write(forged);
  writer.write(cue_type_info<LineSeg3DSeq>().serialize(&two));
  ASSERT_TRUE(eventually([&] { return whole.load() == 1; }, 15s));
  const long grown_kib = peak_rss_kib() - before;
  EXPECT_EQ(other.load(), 0) << "no forged sample reached the reader";
  EXPECT_EQ(malformed_sample_count(topic), 3u);
  EXPECT_LT(grown_kib, 64 * 1024) << "the peak grew by " << grown_kib << " KiB";
  std::printf("peak resident size grew by %ld KiB for 3 forged samples of 4 MiB\n", grown_kib);
}

}  // namespace
}  // namespace oscar
