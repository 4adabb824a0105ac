#include "system_graph.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "json_schema_check.hpp"
#include "json_schemas.hpp"

namespace oscar::bridge {
namespace {
using nlohmann::json;

KernelState kernel(const std::string& name, const std::string& type,
                   std::vector<std::string> inputs = {}) {
  KernelState k;
  k.name(name);
  k.type(type);
  k.mode("continuous");
  k.cycle_ns(20'000'000);
  k.params("{rate: 5}");
  k.inputs(std::move(inputs));
  return k;
}

ModuleEntry module(const std::string& name, std::vector<KernelState> kernels) {
  ModuleEntry m;
  m.name(name);
  m.host("pc1");
  m.pid(42);
  m.status("running");
  m.cues_per_s(50);
  ModuleState s;
  s.module_name(name);
  s.kernels(std::move(kernels));
  m.state(s);
  return m;
}

TEST(SystemGraph, ListsModulesKernelsAndTheWiringBetweenThem) {
  SystemState state;
  state.system("viewed");
  state.state("running");
  state.modules({module("sources", {kernel("sig", "bench_source")}),
                 module("sinks", {kernel("sink", "bench_sink", {"in=sig/out"})})});
  std::map<std::string, DdsParticipant::DiscoveredWriter> writers;
  writers["oscar/cue/sig/out"].type = "oscar::Bool";
  writers["oscar/cue/sig/out"].alive = 1;
  writers["oscar/cue/sig/aux"].type = "oscar::Bool";
  writers["oscar/cue/sig/aux"].alive = 1;
  writers["oscar/cue/other/out"].type = "oscar::Bool";  // no kernel of this system
  writers["oscar/cue/other/out"].alive = 1;
  const auto g = json::parse(system_graph_json(state, writers,
                                               {{.topic = "foxglove/cam/out",
                                                 .source = "oscar/cue/cam/out",
                                                 .subscribers = 1,
                                                 .converted = 12,
                                                 .skipped = 0}}));
  EXPECT_EQ(test::schema_mismatch(json::parse(json_schema("oscar.SystemGraph")), g), "");
  EXPECT_EQ(g["system"], "viewed");
  EXPECT_EQ(g["state"], "running");
  ASSERT_EQ(g["modules"].size(), 2u);
  EXPECT_EQ(g["modules"][0]["name"], "sources");
  EXPECT_EQ(g["modules"][0]["status"], "running");
  EXPECT_EQ(g["modules"][0]["kernels"][0]["cycle_ms"], 20.0);
  EXPECT_EQ(g["modules"][1]["kernels"][0]["inputs"][0],
            json::parse(R"({"input":"in","source":"sig/out"})"));
  ASSERT_EQ(g["channels"].size(), 2u) << g["channels"].dump();
  EXPECT_EQ(g["channels"][0]["source"], "sig/aux");
  EXPECT_EQ(g["channels"][1], json::parse(R"({"source":"sig/out","topic":"oscar/cue/sig/out",
      "type":"oscar::Bool","producer":"sig","consumers":["sink.in"]})"));
  EXPECT_EQ(g["side_channels"][0]["converted"], 12);
}

}  // namespace
}  // namespace oscar::bridge
