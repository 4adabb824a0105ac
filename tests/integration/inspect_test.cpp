// The logger kernel and the inspection tools (oscar topics, echo, hz, graph) against systems
// booted by oscar boot (issue 4).
#include <filesystem>
#include <numeric>
#include <regex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/mcap/reader.hpp"
#include "run_tool.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::Process;
using test::run_tool;
using ::testing::HasSubstr;

std::string domain() { return std::to_string(test::test_domain()); }

// Activates kernels of a module (only the coordinator may: the system's ConfigClient is one).
void activate(BootedSystem& system, const std::string& module,
              const std::vector<std::string>& kernels, const std::string& mode) {
  for (const auto& k : kernels) {
    const auto reply = system.configure(module, CMD_ACTIVATE, {k, mode});
    ASSERT_TRUE(reply.ok()) << k << ": " << reply.error();
  }
}

TEST(LoggerKernel, RecordsTheChannelsItIsWiredToInABootedSystem) {
  const auto file = test::temp_path("logger_booted") + ".mcap";
  std::filesystem::remove(file);
  BootedSystem system("logger", R"(
system: logged
lease: 1s
modules:
  - name: sig_source
    kernels: [ { type: bench_source, name: sig, params: { type: Bool, count: 40 } } ]
    mode: deactivated
  - name: cam_source
    kernels: [ { type: bench_source, name: cam, params: { type: GvImage, count: 10, dx: 64, dy: 48 } } ]
    mode: deactivated
  - name: recorder
    kernels:
      - type: logger
        name: log
        params: { file: )" + file + R"(, compression: lz4 }
        inputs: { flag: sig/out, image: cam/out }
    mode: { continuous: 20ms }
)");
  system.running();
  std::this_thread::sleep_for(1s);  // the logger's readers match the sources' writers
  activate(system, "sig_source", {"sig"}, "continuous:20ms");
  activate(system, "cam_source", {"cam"}, "continuous:20ms");
  std::this_thread::sleep_for(40 * 20ms + 1500ms);
  ASSERT_EQ(system.shut_down(), 0) << system.boot_output();

  mcap::Reader reader(file);
  std::map<std::string, std::vector<std::uint64_t>> seqs;
  reader.read_messages([&](const mcap::Channel& c, const mcap::MessageView& m) {
    const std::vector<std::uint8_t> bytes(m.data.begin(), m.data.end());
    EXPECT_EQ(c.message_encoding, "cdr");
    if (c.topic == "oscar/cue/sig/out") {
      const auto b = std::static_pointer_cast<Bool>(cue_type_info<Bool>().deserialize(bytes));
      EXPECT_EQ(b->header().source(), "sig/out");
      EXPECT_EQ(m.publish_time, b->header().stamps().at(0));
      seqs[c.topic].push_back(b->header().seq());
    } else {
      ASSERT_EQ(c.topic, "oscar/cue/cam/out");
      const auto g = std::static_pointer_cast<GvImage>(cue_type_info<GvImage>().deserialize(bytes));
      EXPECT_EQ(g->image().size(), 64u * 48u);
      seqs[c.topic].push_back(g->header().seq());
    }
    EXPECT_EQ(m.sequence, seqs[c.topic].back());
  });
  std::vector<std::uint64_t> forty(40), ten(10);
  std::iota(forty.begin(), forty.end(), 1);
  std::iota(ten.begin(), ten.end(), 1);
  EXPECT_EQ(seqs["oscar/cue/sig/out"], forty) << "every cue, once, in order";
  EXPECT_EQ(seqs["oscar/cue/cam/out"], ten);
  const auto info = reader.info();
  EXPECT_TRUE(info.from_summary) << "the kernel finished the file when the system shut down";
  ASSERT_EQ(info.schemas.size(), 2u);
  // oscar info reads it like a recording of oscar record.
  const auto printed = run_tool({"oscar-info", file});
  EXPECT_THAT(printed, HasSubstr("oscar/cue/sig/out"));
  EXPECT_THAT(printed, HasSubstr("oscar::GvImage"));
  std::filesystem::remove(file);
}

// One system for the inspection tools: a 50 Hz Bool source, a 10 Hz image source, a relay and
// a sink.
class Inspect : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    system_ = new BootedSystem("inspect", R"(
system: inspected
lease: 1s
modules:
  - name: sources
    kernels: [ { type: bench_source, name: sig, params: { type: Bool } } ]
    mode: deactivated
  - name: camera
    kernels: [ { type: bench_source, name: cam, params: { type: GvImage, dx: 32, dy: 8 } } ]
    mode: deactivated
  - name: view
    kernels:
      - { type: relay, name: sig_relay, params: { type: Bool }, inputs: { in: sig/out } }
      - { type: bench_sink, name: sig_sink, params: { type: Bool }, inputs: { in: sig_relay/out } }
    mode: single_step
)");
    system_->running();
    activate(*system_, "sources", {"sig"}, "continuous:20ms");
    activate(*system_, "camera", {"cam"}, "continuous:100ms");
  }
  static void TearDownTestSuite() {
    system_->shut_down();
    delete system_;
    system_ = nullptr;
  }
  static BootedSystem* system_;
};
BootedSystem* Inspect::system_ = nullptr;

TEST_F(Inspect, TopicsListsEveryCueTopicWithItsTypeAndRate) {
  const auto out = run_tool({"oscar-topics", "-d", domain(), "--duration", "4", "--json"});
  const auto topics = nlohmann::json::parse(out.substr(out.find('[')));
  std::map<std::string, nlohmann::json> by_name;
  for (const auto& t : topics) by_name[t["topic"]] = t;
  ASSERT_TRUE(by_name.count("oscar/cue/sig/out")) << out;
  EXPECT_EQ(by_name["oscar/cue/sig/out"]["type"], "oscar::Bool");
  EXPECT_NEAR(by_name["oscar/cue/sig/out"]["rate_hz"].get<double>(), 50, 12);
  EXPECT_EQ(by_name["oscar/cue/cam/out"]["type"], "oscar::GvImage");
  EXPECT_NEAR(by_name["oscar/cue/cam/out"]["rate_hz"].get<double>(), 10, 3);
  EXPECT_EQ(by_name["oscar/cue/sig_relay/out"]["type"], "oscar::Bool");
  const auto table = run_tool({"oscar-topics", "-d", domain(), "--duration", "2"});
  EXPECT_THAT(table, ::testing::ContainsRegex("oscar/cue/cam/out +oscar::GvImage +[0-9]+\\.[0-9]"));
}

TEST_F(Inspect, EchoPrintsSamplesReadablyWithTheirHeaders) {
  const auto out = run_tool({"oscar-echo", "sig_relay/out", "-n", "3", "-d", domain()});
  EXPECT_THAT(out, HasSubstr("--- oscar/cue/sig_relay/out (oscar::Bool) received "));
  EXPECT_THAT(out, HasSubstr("  source: \"sig_relay/out\"\n"));
  EXPECT_THAT(out, ::testing::ContainsRegex("  stamps: \\[[0-9]+, [0-9]+\\]  # generated 20"))
      << "a relayed cue carries two stamps";
  EXPECT_THAT(out, HasSubstr("value: true"));
  std::vector<std::uint64_t> seqs;
  for (std::size_t at = out.find("  seq: "); at != std::string::npos;
       at = out.find("  seq: ", at + 1))
    seqs.push_back(std::stoull(out.substr(at + 7)));
  ASSERT_EQ(seqs.size(), 3u) << out;
  EXPECT_EQ(seqs[1], seqs[0] + 1);
  EXPECT_EQ(seqs[2], seqs[1] + 1);
  const auto image =
      run_tool({"oscar-echo", "cam/out", "-n", "1", "--max-items", "4", "-d", domain()});
  EXPECT_THAT(
      image,
      ::testing::ContainsRegex(
          "dx: 32\ndy: 8\nimage: \\[[0-9]+, [0-9]+, [0-9]+, [0-9]+, \\.\\.\\.\\]  # 256 items"));
}

TEST_F(Inspect, EchoOfATopicNobodyWritesIsAClearError) {
  const auto out = run_tool({"oscar-echo", "nobody/out", "--timeout", "1", "-d", domain()}, 1);
  EXPECT_THAT(
      out, HasSubstr("oscar echo: no writer of topic 'oscar/cue/nobody/out' appeared on domain " +
                     domain() + " within 1 s"));
}

TEST_F(Inspect, HzMeasuresRateAndPeriodSpread) {
  const auto out = run_tool({"oscar-hz", "sig/out", "--duration", "3", "-d", domain()});
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      out, m,
      std::regex("rate ([0-9.]+) Hz  min ([0-9.]+) ms  max ([0-9.]+) ms  std ([0-9.]+) ms")))
      << out;
  EXPECT_NEAR(std::stod(m[1]), 50, 12);
  EXPECT_LE(std::stod(m[2]), 20.0 + 5);
  EXPECT_GE(std::stod(m[3]), 20.0 - 5);
  EXPECT_LE(std::stod(m[2]), std::stod(m[3]));
}

TEST_F(Inspect, GraphShowsModulesKernelsChannelsAndWiring) {
  const auto dot = run_tool({"oscar-graph", "-d", domain()});
  EXPECT_THAT(dot, HasSubstr("digraph \"inspected\""));
  EXPECT_THAT(dot, HasSubstr("subgraph \"cluster_sources\""));
  EXPECT_THAT(dot, ::testing::ContainsRegex("sources @localhost pid [0-9]+ \\[running\\]"));
  EXPECT_THAT(dot, HasSubstr("\"k:sig\" -> \"c:sig/out\""));
  EXPECT_THAT(dot, HasSubstr("\"c:sig/out\" -> \"k:sig_relay\" [label=\"in\"]"));
  EXPECT_THAT(dot, HasSubstr("\"c:sig_relay/out\" -> \"k:sig_sink\" [label=\"in\"]"));
  EXPECT_THAT(dot, HasSubstr("label=\"cam/out\\noscar::GvImage\"")) << "kernel/channel";
  EXPECT_THAT(dot, HasSubstr("sig\\n(bench_source)\\ncontinuous 20ms"));
  const auto svg = test::temp_path("graph") + ".svg";
  EXPECT_THAT(run_tool({"oscar-graph", "-d", domain(), "-o", svg}), HasSubstr("wrote " + svg));
  std::ifstream in(svg);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_THAT(text, HasSubstr("<svg"));
  EXPECT_THAT(text, HasSubstr("sig_relay"));
  std::filesystem::remove(svg);
}

}  // namespace
}  // namespace oscar
