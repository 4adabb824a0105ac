// The module frame without DDS: in-process handoff, modes, configuration and the rules.
#include "oscar/module.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/testing/eventually.hpp"
#include "test_kernels.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using testing::HasSubstr;
using testing::ThrowsMessage;

ModuleSpec spec(const std::string& yaml) {
  return ModuleSpec::from_yaml(YAML::Load(yaml), "test.yaml");
}

template <class K>
K& kernel_of(Module& m, const std::string& name) {
  return dynamic_cast<K&>(m.kernel(name).kernel());
}

ConfigCommand command(CommandKind kind, std::vector<std::string> args,
                      std::string sender = "coordinator") {
  ConfigCommand c;
  c.id(1);
  c.sender(std::move(sender));
  c.kind(kind);
  c.args(std::move(args));
  return c;
}

const char* const kChain = R"(
name: chain
mode: { continuous: 2ms }
kernels:
  - { type: test_counter, name: src }
  - { type: test_collect, name: sink, inputs: { in: src/out } }
)";

TEST(Module, HandsCuesBetweenItsKernelsWithoutCopies) {
  Module m(spec(kChain), {});
  m.start(-1);
  auto& sink = kernel_of<test::Collect>(m, "sink");
  ASSERT_TRUE(eventually([&] { return sink.seen().size() >= 20; }));
  m.stop();
  // The very object the producer published is what the consumer holds: no copy.
  auto& out_ring = m.kernel("src").ports().find_output("out")->buffer();
  const auto published = out_ring.latest();
  const auto delivered = m.kernel("sink").ports().find_input("in")->buffer().latest();
  ASSERT_TRUE(published && delivered);
  EXPECT_EQ(published->cue.get(), delivered->cue.get());
  EXPECT_EQ(sink.seen().back().get(), published->cue.get());
}

TEST(Module, TheContinuousKernelTriggersTheOthersOfAContinuousModule) {
  Module m(spec(kChain), {});
  EXPECT_EQ(m.state().kernels()[1].trigger(), "module");
  m.start(-1);
  auto& src = kernel_of<test::Counter>(m, "src");
  auto& sink = kernel_of<test::Collect>(m, "sink");
  ASSERT_TRUE(eventually([&] { return src.count_ >= 10; }));
  m.stop();
  EXPECT_GE(sink.runs(), src.count_ - 1);
  EXPECT_LE(sink.runs(), src.count_ + 1);
}

TEST(Module, SingleStepKernelsRunOnDataOrOnCommand) {
  Module m(spec(R"(
name: steps
mode: single_step
kernels:
  - { type: test_counter, name: src, mode: { single_step: { trigger: command } } }
  - { type: test_collect, name: sink, inputs: { in: src/out } }
)"),
           {});
  m.start(-1);
  auto& src = kernel_of<test::Counter>(m, "src");
  auto& sink = kernel_of<test::Collect>(m, "sink");
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(src.count_, 0) << "a command-triggered kernel waits for its trigger";
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(m.apply(command(CMD_TRIGGER, {"src"})).ok());
    ASSERT_TRUE(eventually([&] { return sink.seen().size() == static_cast<std::size_t>(i + 1); }));
  }
  EXPECT_EQ(src.count_, 3);
  EXPECT_EQ(sink.runs(), 3) << "the sink runs once per cue on its trigger input";
}

TEST(Module, DeactivateAndActivateCallTheKernelHooks) {
  Module m(spec(kChain), {});
  m.start(-1);
  auto& src = kernel_of<test::Counter>(m, "src");
  ASSERT_TRUE(eventually([&] { return src.count_ > 0; }));
  const auto reply = m.apply(command(CMD_DEACTIVATE, {"src"}));
  ASSERT_TRUE(reply.ok()) << reply.error();
  EXPECT_EQ(reply.state().kernels()[0].mode(), "deactivated");
  EXPECT_EQ(src.deactivations_, 1);
  const int frozen = src.count_;
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(src.count_, frozen);
  ASSERT_TRUE(m.apply(command(CMD_ACTIVATE, {"src", "continuous:1ms"})).ok());
  ASSERT_TRUE(eventually([&] { return src.count_ > frozen; }));
  EXPECT_EQ(src.activations_, 2);
  EXPECT_THAT(m.state().last_transition(), HasSubstr("src: deactivated -> continuous(1ms)"));
}

TEST(Module, SuspendKeepsBuffersAndResumeContinues) {
  Module m(spec(kChain), {});
  m.start(-1);
  auto& src = kernel_of<test::Counter>(m, "src");
  ASSERT_TRUE(eventually([&] { return src.count_ >= 5; }));
  ASSERT_TRUE(m.apply(command(CMD_SUSPEND, {}, "registry")).ok());
  EXPECT_TRUE(m.state().suspended());
  const int frozen = src.count_;
  const auto held = m.kernel("sink").ports().find_input("in")->buffer().size();
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(src.count_, frozen);
  EXPECT_EQ(m.kernel("sink").ports().find_input("in")->buffer().size(), held) << "buffers kept";
  EXPECT_GT(held, 0u);
  ASSERT_TRUE(m.apply(command(CMD_RESUME, {}, "registry")).ok());
  ASSERT_TRUE(eventually([&] { return src.count_ > frozen; }));
}

TEST(Module, StubModeRunsStubInsteadOfProcess) {
  Module m(spec(kChain), {});
  m.start(-1);
  auto& src = kernel_of<test::Counter>(m, "src");
  ASSERT_TRUE(m.apply(command(CMD_STUB, {"src", "on"})).ok());
  ASSERT_TRUE(eventually([&] { return src.stubs_ >= 3; }));
  EXPECT_TRUE(m.state().kernels()[0].stub());
  ASSERT_TRUE(m.apply(command(CMD_STUB, {"*", "off"})).ok());
  const int stubs = src.stubs_;
  const int count = src.count_;
  ASSERT_TRUE(eventually([&] { return src.count_ > count + 2; }));
  EXPECT_LE(src.stubs_, stubs + 1);
}

TEST(Module, SetParamAndSetCycleChangeTheRunningKernel) {
  Module m(spec(kChain), {});
  m.start(-1);
  auto reply = m.apply(command(CMD_SET_PARAM, {"sink", "factor", "7"}));
  ASSERT_TRUE(reply.ok()) << reply.error();
  EXPECT_EQ(kernel_of<test::Collect>(m, "sink").params_.factor, 7);
  reply = m.apply(command(CMD_SET_PARAM, {"sink", "factor", "seven"}));
  EXPECT_FALSE(reply.ok());
  EXPECT_THAT(reply.error(), HasSubstr("parameter 'factor' expects a int, got 'seven'"));
  reply = m.apply(command(CMD_SET_CYCLE, {"src", "5ms"}));
  ASSERT_TRUE(reply.ok()) << reply.error();
  EXPECT_EQ(reply.state().kernels()[0].cycle_ns(), 5'000'000);
  reply = m.apply(command(CMD_SET_CYCLE, {"sink", "5ms"}));
  EXPECT_THAT(reply.error(), HasSubstr("only a continuous kernel has a (positive) cycle"));
}

TEST(Module, OnlyTheCoordinatorRegistryAndBootMayConfigure) {
  Module m(spec(kChain), {});
  m.start(-1);
  auto reply = m.apply(command(CMD_DEACTIVATE, {"src"}, "some_module"));
  EXPECT_FALSE(reply.ok());
  EXPECT_THAT(reply.error(), HasSubstr("refused: 'some_module' may not deactivate module 'chain': "
                                       "only the coordinator configures modules"));
  EXPECT_EQ(reply.state().kernels()[0].mode(), "continuous");
  EXPECT_FALSE(m.apply(command(CMD_TRIGGER, {"sink"}, "registry")).ok())
      << "the registry suspends, resumes and re-applies; it does not trigger";
  EXPECT_TRUE(m.apply(command(CMD_SUSPEND, {}, "registry")).ok());
  EXPECT_TRUE(m.apply(command(CMD_RESUME, {}, "boot")).ok());
  EXPECT_TRUE(m.apply(command(CMD_SET_CYCLE, {"src", "3ms"}, "coordinator")).ok());
}

TEST(Module, CommandsNameUnknownKernels) {
  Module m(spec(kChain), {});
  const auto reply = m.apply(command(CMD_TRIGGER, {"cam"}));
  EXPECT_THAT(reply.error(), HasSubstr("module 'chain' has no kernel 'cam' (kernels: src, sink)"));
}

TEST(Module, RewireMovesAnInputToAnotherProducer) {
  Module m(spec(R"(
name: two
mode: single_step
kernels:
  - { type: test_counter, name: a, mode: { single_step: { trigger: command } } }
  - { type: test_counter, name: b, mode: { single_step: { trigger: command } } }
  - { type: test_collect, name: sink, inputs: { in: a/out } }
)"),
           {});
  m.start(-1);
  auto& sink = kernel_of<test::Collect>(m, "sink");
  m.apply(command(CMD_TRIGGER, {"a"}));
  ASSERT_TRUE(eventually([&] { return sink.seen().size() == 1; }));
  ASSERT_TRUE(m.apply(command(CMD_REWIRE, {"sink", "in", "b/out"})).ok());
  m.apply(command(CMD_TRIGGER, {"a"}));
  m.apply(command(CMD_TRIGGER, {"b"}));
  ASSERT_TRUE(eventually([&] { return sink.seen().size() == 2; }));
  std::this_thread::sleep_for(10ms);
  ASSERT_EQ(sink.seen().size(), 2u) << "nothing from the old producer after the switch";
  EXPECT_EQ(sink.seen()[1]->header().source(), "b/out");
}

TEST(Module, ARawInputGetsCuesOfAnyTypeSerializedUnderTheProducersTypeName) {
  Module m(spec(R"(
name: raw
mode: { continuous: 2ms }
kernels:
  - { type: test_counter, name: src }
  - { type: test_lines, name: lines, mode: { single_step: { trigger: module } } }
  - type: test_raw_collect
    name: sink
    inputs: { flags: src/out, lines: lines/out }
    mode: { single_step: { trigger: module } }
)"),
           {});
  m.start(-1);
  auto& sink = kernel_of<test::RawCollect>(m, "sink");
  const auto count = [&](const std::string& type) {
    const auto seen = sink.seen();
    return std::count_if(seen.begin(), seen.end(), [&](const auto& c) { return c->type == type; });
  };
  ASSERT_TRUE(
      eventually([&] { return count("oscar::Bool") >= 5 && count("oscar::LineSeg3DSeq") >= 5; }));
  m.stop();
  std::uint64_t last_bool = 0;
  for (const auto& raw : sink.seen()) {
    if (raw->type == "oscar::Bool") {
      const auto b = std::static_pointer_cast<Bool>(cue_type_info<Bool>().deserialize(raw->cdr));
      EXPECT_EQ(b->header(), raw->header()) << "the header travels with the bytes";
      EXPECT_EQ(b->header().source(), "src/out");
      EXPECT_EQ(b->value(), b->header().seq() % 2 == 1) << "the counter's value";
      EXPECT_EQ(b->header().seq(), last_bool + 1) << "every cue, in order";
      last_bool = b->header().seq();
    } else {
      ASSERT_EQ(raw->type, "oscar::LineSeg3DSeq");
      const auto l = std::static_pointer_cast<LineSeg3DSeq>(
          cue_type_info<LineSeg3DSeq>().deserialize(raw->cdr));
      EXPECT_EQ(l->header(), raw->header());
      EXPECT_EQ(l->header().source(), "lines/out");
    }
  }
}

TEST(Module, APullInputRewiredInsideTheModulePullsFromTheNewProducerAndIsPushedNothing) {
  Module m(spec(R"(
name: pulling
mode: single_step
kernels:
  - { type: test_counter, name: a, mode: { single_step: { trigger: command } } }
  - { type: test_counter, name: b, mode: { single_step: { trigger: command } } }
  - { type: test_collect, name: sink, inputs: { in: { source: a/out, transfer: pull } }, mode: deactivated }
)"),
           {});
  m.start(-1);
  auto& in = kernel_of<test::Collect>(m, "sink").in_;
  const auto reply = m.apply(command(CMD_REWIRE, {"sink", "in", "b/out"}));
  ASSERT_TRUE(reply.ok()) << reply.error();
  EXPECT_EQ(reply.note(), "");
  for (const auto* k : {"a", "b"}) {
    m.apply(command(CMD_TRIGGER, {k}));
    auto& ring = m.kernel(k).ports().find_output("out")->buffer();
    ASSERT_TRUE(eventually([&] { return ring.pushed() == 1; })) << k;
  }
  EXPECT_EQ(in.transfer(), Transfer::kPull);
  EXPECT_EQ(in.buffer().pushed(), 0u) << "a pull input is pushed nothing, by either producer";
  const auto latest = in.pull();
  ASSERT_TRUE(latest);
  EXPECT_EQ(latest->header().source(), "b/out");
}

TEST(Module, AnInputOptionTheYamlNamesReplacesOnlyThatOneOfTheDeclared) {
  const auto options = [](const std::string& wiring) {
    Module m(spec(R"(
name: opts
mode: single_step
kernels:
  - { type: test_counter, name: src, mode: { single_step: { trigger: command } } }
  - { type: test_prefetching, name: p, inputs: { in: )" +
                  wiring + R"( } }
)"),
             {});
    const auto& in = kernel_of<test::Prefetching>(m, "p").in_;
    return std::pair{in.buffer().depth(), in.transfer()};
  };
  EXPECT_EQ(options("src/out"), std::pair(std::size_t{64}, Transfer::kPrefetch)) << "declared";
  EXPECT_EQ(options("{ source: src/out, depth: 8 }"),
            std::pair(std::size_t{8}, Transfer::kPrefetch));
  EXPECT_EQ(options("{ source: src/out, transfer: pull }"),
            std::pair(std::size_t{64}, Transfer::kPull));
}

TEST(Module, PullAsksTheProducersRingForAGivenTime) {
  Module m(spec(R"(
name: pulling
mode: single_step
kernels:
  - { type: test_counter, name: src, mode: { single_step: { trigger: command } } }
  - { type: test_collect, name: sink, inputs: { in: { source: src/out, transfer: pull } }, mode: deactivated }
)"),
           {});
  m.start(-1);
  auto& src_ring = m.kernel("src").ports().find_output("out")->buffer();
  for (int i = 0; i < 3; ++i) {
    m.apply(command(CMD_TRIGGER, {"src"}));
    ASSERT_TRUE(eventually([&] { return src_ring.pushed() == static_cast<std::uint64_t>(i + 1); }));
  }
  auto& in = kernel_of<test::Collect>(m, "sink").in_;
  EXPECT_EQ(in.buffer().size(), 0u) << "a pull input receives nothing unasked";
  const auto all = src_ring.latest(3);
  const auto second = in.pull_at(all[1].t);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->header().seq(), 2u);
  EXPECT_EQ(in.pull()->header().seq(), 3u);
  const auto future = in.prefetch(PullQuery::kNearest, all[0].t + 1);
  EXPECT_EQ(future.get()->header().seq(), 1u);
  EXPECT_FALSE(in.pull_at(all[0].t - 1)) << "nothing at or before a time older than the ring";
}

const char* const kPullingModule = R"(
name: pulling
mode: single_step
kernels:
  - { type: test_counter, name: src, mode: { single_step: { trigger: command } } }
  - { type: test_collect, name: sink, inputs: { in: { source: src/out, transfer: prefetch } }, mode: deactivated }
)";

// A producer whose generation stamps the test sets; write() returns once the output handed the
// cue to every consumer (a probe, connected last, has it), held pulls included.
struct StampedProducer {
  Module& m;
  OutputPort& out;
  InputPort probe{"test", "probe", cue_type_info<Bool>(), {}};
  std::atomic<Stamp> stamp_next{1'000};
  explicit StampedProducer(Module& module)
      : m(module), out(*module.kernel("src").ports().find_output("out")) {
    out.set_clock([this] { return stamp_next.load(); });
  }
  ~StampedProducer() { out.disconnect(&probe); }
  void write(Stamp t) {
    stamp_next = t;
    out.disconnect(&probe);
    out.connect(&probe);  // last of the consumers
    const auto before = probe.buffer().pushed();
    m.apply(command(CMD_TRIGGER, {"src"}));
    ASSERT_TRUE(eventually([&] { return probe.buffer().pushed() == before + 1; }));
  }
};

TEST(Module, APullForACueAtOrAfterATimeIsAnsweredWhenTheProducerWritesOne) {
  Module m(spec(kPullingModule), {});
  m.start(-1);
  StampedProducer src(m);
  auto& in = kernel_of<test::Collect>(m, "sink").in_;
  src.write(1'000);
  const auto future = in.prefetch(PullQuery::kAtOrAfter, 2'000, 10s);
  EXPECT_FALSE(future.ready()) << "the producer holds no cue generated at or after 2000";
  src.write(1'500);
  EXPECT_FALSE(future.ready()) << "a cue older than asked does not answer it";
  src.write(2'500);
  ASSERT_TRUE(future.ready()) << "answered where the output took the matching cue";
  const auto cue = future.get(0s);
  ASSERT_TRUE(cue);
  EXPECT_EQ(cue->header().seq(), 3u);
  EXPECT_EQ(in.latest(), cue) << "the answer lands in the input's ring too";
}

TEST(Module, APullForACueAtOrAfterATimeIsAnsweredAtOnceIfTheProducerHoldsOne) {
  Module m(spec(kPullingModule), {});
  m.start(-1);
  StampedProducer src(m);
  auto& in = kernel_of<test::Collect>(m, "sink").in_;
  for (const Stamp t : {1'000, 2'000, 3'000}) src.write(t);
  const auto future = in.prefetch(PullQuery::kAtOrAfter, 1'500, 10s);
  ASSERT_TRUE(future.ready());
  EXPECT_EQ(future.get(0s)->header().seq(), 2u) << "the first cue generated at or after 1500";
  EXPECT_FALSE(in.prefetch(PullQuery::kAtOrAfter, 3'001).get(0s)) << "no wait: answered empty";
}

TEST(Module, APullForACueAtOrAfterATimeIsAnsweredEmptyWhenItsWaitIsUp) {
  Module m(spec(kPullingModule), {});
  m.start(-1);
  StampedProducer src(m);
  auto& in = kernel_of<test::Collect>(m, "sink").in_;
  src.write(1'000);
  const auto future = in.prefetch(PullQuery::kAtOrAfter, 2'000, 50ms);
  EXPECT_FALSE(future.get(10s)) << "nothing";
  EXPECT_TRUE(future.ready()) << "answered (empty), not left waiting";
  EXPECT_EQ(in.buffer().size(), 0u);
}

TEST(Module, HeldPullsAreBoundedPerInputAndTheirWait) {
  Module m(spec(kPullingModule), {});
  m.start(-1);
  auto& in = kernel_of<test::Collect>(m, "sink").in_;
  std::vector<CueFuture<Bool>> held;
  for (std::size_t i = 0; i < kMaxHeldPulls; ++i) {
    held.push_back(in.prefetch(PullQuery::kAtOrAfter, 1'000, 10s));
  }
  EXPECT_THAT([&] { in.prefetch(PullQuery::kAtOrAfter, 1'000, 10s); },
              ThrowsMessage<std::length_error>(HasSubstr("a producer holds at most 16 per input")));
  EXPECT_THAT([&] { in.prefetch(PullQuery::kAtOrAfter, 1'000, 11s); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("a pull may ask the producer to wait 0 to 10 s, not 11000 ms")));
  StampedProducer src(m);
  src.write(1'000);
  for (const auto& f : held) EXPECT_TRUE(f.ready()) << "one cue answers every held pull";
  EXPECT_NO_THROW(in.prefetch(PullQuery::kAtOrAfter, 5'000, 10s)) << "room again";
}

TEST(Module, HeldPullsAreAnsweredEmptyWhenTheProducersModuleStops) {
  std::optional<CueFuture<Bool>> future;
  {
    Module m(spec(kPullingModule), {});
    m.start(-1);
    future = kernel_of<test::Collect>(m, "sink").in_.prefetch(PullQuery::kAtOrAfter, 1'000, 10s);
    EXPECT_FALSE(future->ready());
  }
  ASSERT_TRUE(future->ready()) << "answered when the module went, not at the end of its wait";
  EXPECT_FALSE(future->get(0s));
}

std::vector<std::uint64_t> seqs(const std::vector<Input<Bool>::Ptr>& cues) {
  std::vector<std::uint64_t> out;
  for (const auto& c : cues) out.push_back(c->header().seq());
  return out;
}

TEST(Module, BlockPullsAskTheProducersRingForItsNewestCuesAndForATimeRange) {
  Module m(spec(R"(
name: pulling
mode: single_step
kernels:
  - { type: test_counter, name: src, mode: { single_step: { trigger: command } } }
  - { type: test_collect, name: sink, inputs: { in: { source: src/out, transfer: pull } }, mode: deactivated }
)"),
           {});
  m.start(-1);
  auto& src_ring = m.kernel("src").ports().find_output("out")->buffer();
  for (int i = 0; i < 5; ++i) {
    m.apply(command(CMD_TRIGGER, {"src"}));
    ASSERT_TRUE(eventually([&] { return src_ring.pushed() == static_cast<std::uint64_t>(i + 1); }));
  }
  auto& in = kernel_of<test::Collect>(m, "sink").in_;
  const auto all = src_ring.latest(5);
  EXPECT_THAT(seqs(in.pull_latest(3)), testing::ElementsAre(3u, 4u, 5u)) << "oldest first";
  EXPECT_EQ(in.buffer().pushed(), 3u) << "the answer lands in the input's ring too";
  EXPECT_THAT(seqs(in.pull_latest(100)), testing::ElementsAre(1u, 2u, 3u, 4u, 5u))
      << "more than the producer holds: what it holds";
  EXPECT_THAT(seqs(in.pull_range(all[1].t, all[3].t)), testing::ElementsAre(2u, 3u, 4u))
      << "both ends included";
  EXPECT_THAT(seqs(in.pull_range(all[1].t + 1, all[3].t - 1)), testing::ElementsAre(3u));
  EXPECT_TRUE(in.pull_range(0, all[0].t - 1).empty()) << "nothing before the ring";
  EXPECT_THAT(seqs(in.prefetch(PullBlock::latest(2)).get()), testing::ElementsAre(4u, 5u));
  EXPECT_THAT([&] { in.pull_range(all[3].t, all[1].t); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("inverted time range [" + std::to_string(all[3].t) + ", " +
                            std::to_string(all[1].t) + "]: the start must not be after the end")));
}

// --- the seed's multi-core rules (seed 004 §2.2) and bad input ---

TEST(ModuleRules, AtMostOneContinuousKernel) {
  EXPECT_THAT(
      [] {
        Module m(spec(R"(
name: two_clocks
kernels:
  - { type: test_counter, name: a, mode: continuous:10ms }
  - { type: test_counter, name: b, mode: continuous:10ms }
)"),
                 {});
      },
      ThrowsMessage<std::invalid_argument>(HasSubstr(
          "breaks the multi-core rule 'at most one kernel in continuous mode (it triggers the "
          "others)': kernels a, b are all continuous")));
}

TEST(ModuleRules, OnlyPullOrOnlyPushInside) {
  EXPECT_THAT(
      [] {
        Module m(spec(R"(
name: mixed
mode: single_step
kernels:
  - { type: test_counter, name: a }
  - { type: test_collect, name: x, inputs: { in: a/out } }
  - { type: test_collect, name: y, inputs: { in: { source: a/out, transfer: pull } } }
)"),
                 {});
      },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("'inside a multi-core module only pull or only push'")));
}

TEST(ModuleRules, NoBranchingTogetherWithMerging) {
  EXPECT_THAT(
      [] {
        Module m(spec(R"(
name: diamond
mode: single_step
kernels:
  - { type: test_counter, name: a }
  - { type: test_merge, name: m, inputs: { a: a/out, b: a/out } }
)"),
                 {});
      },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("'no branching together with merging of cue flow'")));
}

TEST(ModuleRules, ARewireThatWouldBreakARuleIsRefusedAndTheWiringStays) {
  Module m(spec(R"(
name: almost_diamond
mode: single_step
kernels:
  - { type: test_counter, name: a, mode: { single_step: { trigger: command } } }
  - { type: test_counter, name: b, mode: { single_step: { trigger: command } } }
  - { type: test_merge, name: m, inputs: { a: a/out, b: b/out } }
)"),
           {});
  m.start(-1);
  const auto reply =
      m.apply(command(CMD_REWIRE, {"m", "b", "a/out"}));  // a would branch to m twice
  EXPECT_FALSE(reply.ok());
  EXPECT_THAT(reply.error(), HasSubstr("'no branching together with merging of cue flow'"));
  EXPECT_THAT(m.state().kernels()[2].inputs(), testing::ElementsAre("a=a/out", "b=b/out"));
}

TEST(ModuleBadInput, WiringBetweenDifferentTypesNamesBoth) {
  EXPECT_THAT(
      [] {
        Module m(spec(R"(
name: wrong
mode: single_step
kernels:
  - { type: test_lines, name: lines }
  - { type: test_collect, name: sink, inputs: { in: lines/out } }
)"),
                 {});
      },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("cannot wire lines/out (oscar::LineSeg3DSeq) to input sink/in (oscar::Bool)")));
}

TEST(ModuleBadInput, AnInputOfAnyTypeAsksForPushOnly) {
  EXPECT_THAT(
      [] {
        Module m(spec(R"(
name: raw_pull
mode: single_step
kernels:
  - { type: test_counter, name: src }
  - { type: test_raw_collect, name: sink, inputs: { in: { source: src/out, transfer: pull } } }
)"),
                 {});
      },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("kernel 'sink' (test_raw_collect): input 'in' takes cues of any type, which "
                    "arrive by push only, not pull")));
}

TEST(ModuleBadInput, AReliableInputWiredToABestEffortOutputIsRefusedNamingBoth) {
  EXPECT_THAT(
      [] {
        Module m(spec(R"(
name: m
kernels:
  - { type: test_emitter, name: src, params: { reliable: false } }
  - { type: test_reliable_collect, name: sink, inputs: { in: src/out } }
)"),
                 {});
      },
      ThrowsMessage<std::invalid_argument>(HasSubstr(
          "input 'sink.in' (reliable) is wired to 'src/out', which is best effort: a reliable "
          "reader never matches a best-effort writer; declare the input best effort or make the "
          "output reliable")));
}

TEST(ModuleBadInput, DuplicateKernelNames) {
  EXPECT_THAT(
      [] {
        spec("{name: d, kernels: [{type: test_counter, name: a}, {type: test_counter, name: a}]}");
      },
      ThrowsMessage<std::invalid_argument>(HasSubstr("duplicate kernel name 'a'")));
}

TEST(ModuleBadInput, AMisspeltKernelTypeGetsTheClosestLoadableTypeAndTheListOfAll) {
  const auto path = plugin_search_path();  // the build's plugin folder: relay, logger, ...
  EXPECT_THAT([&] { Module m(spec("{name: u, kernels: [{type: test_colect}]}"), path); },
              ThrowsMessage<std::runtime_error>(testing::AllOf(
                  HasSubstr("unknown kernel type 'test_colect' (did you mean 'test_collect'?)"),
                  testing::ContainsRegex("types that can be loaded: .*relay.*test_collect"),
                  HasSubstr("plugins:"), HasSubstr("OSCAR_PLUGIN_PATH"))));
  EXPECT_THAT([&] { Module m(spec("{name: u, kernels: [{type: gripper}]}"), path); },
              ThrowsMessage<std::runtime_error>(testing::Not(HasSubstr("did you mean"))))
      << "no suggestion when nothing is near";
}

TEST(ModuleBadInput, UnknownKernelTypeNamesTheSearchPath) {
  EXPECT_THAT([] { Module m(spec("{name: u, kernels: [{type: no_such_type}]}"), {"/nowhere"}); },
              ThrowsMessage<std::runtime_error>(
                  HasSubstr("unknown kernel type 'no_such_type': no plugin "
                            "liboscar_kernel_no_such_type.so in [/nowhere]")));
}

TEST(ModuleBadInput, APluginThatFailsToLoadShowsTheLoaderMessage) {
  const auto dir = std::filesystem::temp_directory_path() / "oscar_bad_plugin";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "liboscar_kernel_broken.so") << "this is not an ELF file";
  EXPECT_THAT(
      [&] { Module m(spec("{name: b, kernels: [{type: broken}]}"), {dir.string()}); },
      ThrowsMessage<std::runtime_error>(HasSubstr("liboscar_kernel_broken.so' failed to load")));
}

TEST(ModuleBadInput, UnknownKeysAndParamsAreErrorsWithTheLine) {
  EXPECT_THAT([] { spec("name: k\nkernels:\n  - {type: test_counter, prams: {x: 1}}\n"); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("test.yaml:3: kernels[0]: unknown key 'prams'")));
  EXPECT_THAT(
      [] { Module m(spec("{name: k, kernels: [{type: test_collect, params: {factr: 2}}]}"), {}); },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("has no parameter 'factr'; its parameters: factor")));
  EXPECT_THAT(
      [] { Module m(spec("{name: k, kernels: [{type: test_counter, params: {x: 2}}]}"), {}); },
      ThrowsMessage<std::invalid_argument>(
          HasSubstr("has no parameters, but the configuration gives some")));
  EXPECT_THAT([] { spec("{name: k, kernels: [{type: test_collect, inputs: {in: nowhere}}]}"); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("source 'nowhere' must be '<kernel>/<channel>'")));
  EXPECT_THAT([] { spec("{name: k, mode: continuous, kernels: [{type: test_counter}]}"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("mode 'continuous' needs a cycle")));
}

TEST(ModuleBadInput, MalformedYamlNamesFileLineAndColumn) {
  const auto file = std::filesystem::temp_directory_path() / "oscar_malformed.yaml";
  std::ofstream(file) << "name: m\nkernels:\n  - { type: test_counter\n  - oops: [\n";
  EXPECT_THAT([&] { ModuleSpec::load(file.string()); },
              ThrowsMessage<std::invalid_argument>(HasSubstr(file.string() + ":4:")));
}

// What the registry hands a restarted module (oscar-run --restore): the coordinator's changes.
TEST(ModuleSpec, RestoreAppliesModesStubParametersAndWiring) {
  auto spec = ModuleSpec::from_yaml(YAML::Load(R"(
name: m
kernels:
  - { type: test_counter, name: src }
  - { type: test_collect, name: sink, params: { factor: 1 }, inputs: { in: src/out } }
)"),
                                    "test");
  spec.restore(YAML::Load(
      "{src: {mode: 'continuous:5000000ns', stub: true}, sink: {params: {factor: 3}, inputs: "
      "{in: other/out}}}"));
  EXPECT_EQ(spec.kernels[0].mode->describe(), "continuous(5ms)");
  EXPECT_EQ(spec.kernels[0].stub, true);
  EXPECT_EQ(spec.kernels[1].params["factor"].as<int>(), 3);
  EXPECT_EQ(spec.kernels[1].inputs.at("in").source, "other/out");
  EXPECT_THAT([&] { spec.restore(YAML::Load("{ghost: {stub: true}}")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("module 'm' has no kernel 'ghost'")));
  EXPECT_THAT([&] { spec.restore(YAML::Load("{src: {colour: red}}")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("unknown key 'colour'")));
}

}  // namespace
}  // namespace oscar
