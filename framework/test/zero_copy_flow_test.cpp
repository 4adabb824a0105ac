// Plain cues on the zero-copy path between modules (docs/zero_copy.md, "Wiring into the ports"):
// a kernel's output of a plain type publishes through this host's RouDi, and an input of another
// module on the host reads the chunks in place. The test process has a mount namespace of its
// own with a RouDi of its own (private_tmp.hpp; root, skipped otherwise).
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include "oscar/module.hpp"
#include "oscar/testing/eventually.hpp"
#include "plain_kernels.hpp"
#include "private_tmp.hpp"
#include "process.hpp"
#include "zero_copy/chunk_identity.hpp"
#include "zero_copy/chunk_subscriber.hpp"
#include "zero_copy/mempools.hpp"
#include "zero_copy/roudi.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using testing::HasSubstr;

std::unique_ptr<Module> module(const std::string& yaml) {
  auto m = std::make_unique<Module>(ModuleSpec::from_yaml(YAML::Load(yaml), "test"),
                                    plugin_search_path());
  m->start(test::test_domain());
  return m;
}

const std::string kSource = R"(
name: plain_src
mode: { continuous: 20ms }
kernels: [ { type: test_plain_source, name: src } ]
)";
const std::string kSink = R"(
name: plain_sink
mode: { continuous: 10ms }
kernels:
  - { type: test_plain_sink, name: sink, inputs: { flag: src/flag, image: src/image } }
)";

// Its images pulled, its Bools pushed.
const std::string kImagePuller = R"(
name: puller
mode: deactivated
kernels:
  - type: test_plain_sink
    name: sink
    inputs: { flag: src/flag, image: { source: src/image, transfer: pull } }
)";

std::string zero_copy_topic_of(const std::string& address) {
  return zero_copy::zero_copy_topic(test::test_domain(), "oscar/cue/" + address);
}

// The Bools an input's ring got, in order, each with whether it lay in shared memory; take_new()
// must be called more often than the ring fills.
class FlagArrivals {
 public:
  struct Arrival {
    std::uint64_t index, seq;
    bool in_shared_memory;
  };
  explicit FlagArrivals(const RingBuffer& ring) : ring_(ring) {}
  void take_new() {
    for (const auto& e : ring_.latest(ring_.depth())) {
      if (!all_.empty() && e.index <= all_.back().index) continue;
      all_.push_back({e.index, cue_type_info<PlainBool>().header.read(e.cue.get()).seq(),
                      zero_copy::identify_chunk(e.cue.get()).has_value()});
    }
  }
  std::size_t through_dds() const { return first_zero_copy() - all_.begin(); }
  std::size_t zero_copy() const {
    return std::count_if(all_.begin(), all_.end(),
                         [](const Arrival& a) { return a.in_shared_memory; });
  }
  // Through DDS first, then only zero-copy; across the switch and after it each cue once and
  // none lost (DDS alone may lose one under load: its writer keeps the last 64).
  void expect_one_switch_losing_nothing() const {
    const auto first = first_zero_copy();
    ASSERT_NE(first, all_.begin()) << "no cue came through DDS";
    ASSERT_NE(first, all_.end()) << "no cue came zero-copy";
    EXPECT_TRUE(
        std::all_of(first, all_.end(), [](const Arrival& a) { return a.in_shared_memory; }));
    for (auto a = first; a != all_.end(); ++a) {
      const auto& before = *(a - 1);
      if (a->index == before.index + 1) {
        EXPECT_EQ(a->seq, before.seq + 1) << "arrival " << a->index;
      }
    }
  }

 private:
  std::vector<Arrival>::const_iterator first_zero_copy() const {
    return std::find_if(all_.begin(), all_.end(),
                        [](const Arrival& a) { return a.in_shared_memory; });
  }
  const RingBuffer& ring_;
  std::vector<Arrival> all_;
};

void expect_each_flag_once(test::PlainSink& sink) {
  const auto flags = sink.flags();
  for (std::size_t i = 1; i < flags.size(); ++i) {
    EXPECT_GT(flags[i].header.seq(), flags[i - 1].header.seq()) << "none twice";
  }
}

std::unique_ptr<test::Process> plain_source_process() {
  return test::run_module(
      "plain_src",
      {"--plugin", test::build_dir() + "/lib/oscar/test_plugins/liboscar_kernel_test_plain.so",
       "-k", "test_plain_source:src", "-m", "continuous:20ms"});
}

// Whether a process of this host offers the chunks of output `address` (the test process joins
// RouDi to ask).
bool offered_here(const std::string& address, const std::string& type) {
  return zero_copy::join_roudi("zero_copy_flow_test") == std::nullopt &&
         zero_copy::offered_on_this_host(zero_copy_topic_of(address), type);
}

// One RouDi for the test process, which joins it once and for good (iceoryx 2.0 cannot join
// another). It ends with SIGKILL: stopped with SIGTERM, RouDi would send SIGTERM to every process
// registered with it, this one included.
class Roudi {
 public:
  Roudi() {
    // Bools: a source's ring of 64, a sink's ring of 64 (which may hold older ones) and its
    // queue of 64, and the chunks being filled.
    std::ofstream("/tmp/roudi.toml") << zero_copy::roudi_config(
        {zero_copy::mempool_for<PlainBool>(256), zero_copy::mempool_for<PlainLineSeg3DSeq>(64),
         zero_copy::mempool_for<PlainGvImage>(64)});
    process_ = std::make_unique<test::Process>(
        std::vector<std::string>{"/usr/bin/iox-roudi", "-c", "/tmp/roudi.toml"}, "/tmp/roudi.log");
  }
  ~Roudi() {
    ::kill(process_->pid(), SIGKILL);
    process_->wait(5s);
  }
  std::string output() const { return process_->output(); }

 private:
  std::unique_ptr<test::Process> process_;
};

class ZeroCopyWiring : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::kNoPrivateTmp.empty())
      GTEST_SKIP() << "needs a private mount namespace (root): " << test::kNoPrivateTmp;
    static const Roudi roudi;
    ASSERT_TRUE(eventually([] { return zero_copy::roudi_running(); }, 30s)) << roudi.output();
  }
};

// Both modules in this process, so that both ends of a cue can be looked at: the sink's ring holds
// the very objects the source's ring holds, which the source filled where they lie.
TEST_F(ZeroCopyWiring, ASinkReadsTheSourcesImagesInTheChunksTheSourceFilledThem) {
  auto src = module(kSource);
  ASSERT_TRUE(eventually(
      [] {
        return zero_copy::offered_on_this_host(zero_copy_topic_of("src/image"),
                                               "oscar::PlainGvImage");
      },
      10s));
  auto sink = module(kSink);
  auto& k = dynamic_cast<test::PlainSink&>(sink->kernel("sink").kernel());
  ASSERT_TRUE(eventually([&] { return k.images().size() >= 20 && k.flags().size() >= 20; }, 60s));
  src->stop();
  sink->stop();
  auto& source = dynamic_cast<test::PlainSource&>(src->kernel("src").kernel());
  auto& produced = src->kernel("src").ports().find_output("image")->buffer();
  auto& received = sink->kernel("sink").ports().find_input("image")->buffer();
  // The source filled its last image in the chunk its ring holds: published without a copy.
  ASSERT_TRUE(produced.latest());
  EXPECT_EQ(produced.latest()->cue.get(), source.last_image());
  EXPECT_TRUE(zero_copy::identify_chunk(source.last_image())) << "a chunk, not heap memory";
  std::map<std::uint64_t, const void*> by_seq;
  for (const auto& e : produced.latest(produced.depth())) {
    by_seq[cue_type_info<PlainGvImage>().header.read(e.cue.get()).seq()] = e.cue.get();
  }
  std::size_t same = 0;
  for (const auto& e : received.latest(received.depth())) {
    EXPECT_TRUE(zero_copy::identify_chunk(e.cue.get())) << "in shared memory";
    const auto seq = cue_type_info<PlainGvImage>().header.read(e.cue.get()).seq();
    if (const auto it = by_seq.find(seq); it != by_seq.end()) {
      EXPECT_EQ(it->second, e.cue.get()) << "seq " << seq << ": the source's object";
      ++same;
    }
  }
  EXPECT_GE(same, 2u) << "the rings overlap (source depth 4, sink depth 8)";
  const auto images = k.images();
  for (std::size_t i = 0; i < images.size(); ++i) {
    EXPECT_TRUE(images[i].image_complete) << "seq " << images[i].header.seq();
    EXPECT_EQ(images[i].frame, images[i].header.seq());
    EXPECT_EQ(images[i].header.source(), "src/image");
  }
  // Bools are published by value: copied once into a chunk, read in place all the same.
  const auto flag = sink->kernel("sink").ports().find_input("flag")->buffer().latest();
  ASSERT_TRUE(flag);
  EXPECT_TRUE(zero_copy::identify_chunk(flag->cue.get()));
  const auto flags = k.flags();
  for (std::size_t i = 1; i < flags.size(); ++i) {
    EXPECT_EQ(flags[i].header.seq(), flags[i - 1].header.seq() + 1) << "none lost";
    EXPECT_EQ(flags[i].value, flags[i].header.seq() % 2 == 1);
  }
}

// The source in an oscar-run child: every image the sink gets lies in shared memory, whole, in
// order; after the source has stopped, another one's images come the same way. Stopped, not
// killed: a source killed while it publishes leaves this RouDi hanging now and then (iceoryx 2.0,
// a lock of its publisher held for good), which this process, joined to it, cannot get over. In a
// booted system the monitor replaces such a RouDi, and the registry the modules that joined it
// (ZeroCopySystem.AProducerKilledOverAndOver..., tests/integration/host_roudi_test.cpp).
TEST_F(ZeroCopyWiring, ImagesCrossProcessesInPlaceAndAgainFromARestartedSource) {
  auto src = plain_source_process();
  ASSERT_TRUE(eventually([] { return offered_here("src/image", "oscar::PlainGvImage"); }, 30s))
      << src->output();
  auto sink = module(kSink);
  auto& k = dynamic_cast<test::PlainSink&>(sink->kernel("sink").kernel());
  auto& received = sink->kernel("sink").ports().find_input("image")->buffer();
  // Entries the ring evicted before a look (a starved test thread) are not counted.
  std::size_t in_shared_memory = 0, observed = 0, seen = 0;
  const auto check_new = [&] {
    for (const auto& e : received.latest(received.depth())) {
      if (e.index <= seen) continue;
      seen = e.index;
      ++observed;
      if (zero_copy::identify_chunk(e.cue.get())) ++in_shared_memory;
    }
  };
  ASSERT_TRUE(eventually(
      [&] {
        check_new();
        return k.images().size() >= 10;
      },
      60s))
      << src->output();
  ::kill(src->pid(), SIGTERM);
  ASSERT_EQ(src->wait(10s), 0) << src->output();
  const auto before = k.images().size();
  auto again = plain_source_process();
  ASSERT_TRUE(eventually(
      [&] {
        check_new();
        return k.images().size() >= before + 10;
      },
      60s))
      << again->output();
  sink->stop();
  EXPECT_EQ(in_shared_memory, observed) << "every image the ring got lay in shared memory";
  const auto images = k.images();
  for (const auto& image : images)
    EXPECT_TRUE(image.image_complete) << "seq " << image.header.seq();
}

// An input wired before its producer runs reads through DDS (a producer started more than the
// input's 2 s wait later). Once the producer's cues come and RouDi lists its output, the input
// goes zero-copy; across the switch it gets each cue once, and none is lost.
TEST_F(ZeroCopyWiring, AnInputWhoseProducerStartsLaterGoesZeroCopyAndGetsEachCueOnce) {
  std::ostringstream said;
  auto capture = std::make_shared<spdlog::sinks::ostream_sink_mt>(said);
  spdlog::default_logger()->sinks().push_back(capture);
  auto sink = module(kSink);
  auto& k = dynamic_cast<test::PlainSink&>(sink->kernel("sink").kernel());
  FlagArrivals arrivals(sink->kernel("sink").ports().find_input("flag")->buffer());
  auto src = plain_source_process();
  ASSERT_TRUE(eventually(
      [&] {
        arrivals.take_new();
        return arrivals.zero_copy() >= 50;
      },
      60s))
      << src->output() << said.str();
  sink->stop();
  std::erase(spdlog::default_logger()->sinks(), capture);
  // Through DDS first: the switch waits for the producer's first cue.
  arrivals.expect_one_switch_losing_nothing();
  EXPECT_THAT(said.str(), HasSubstr("cues of src/flag go serialized, not zero-copy: no process of "
                                    "this host offers it in shared memory"));
  expect_each_flag_once(k);
  std::cout << "flags through DDS " << arrivals.through_dds() << ", then zero-copy "
            << arrivals.zero_copy() << '\n';
}

// Modules that found no RouDi when they started (the host's monitor starts it; a module may come
// first) join it once it runs: the producer in an oscar-run child offers its plain outputs from
// then on, and the consumer in this process switches its input to them, losing nothing. No
// fixture: RouDi starts in the middle of the test.
TEST(ZeroCopyLateRoudi, ModulesStartedBeforeRoudiJoinItOnceItRunsAndTheirCuesGoZeroCopy) {
  if (!test::kNoPrivateTmp.empty())
    GTEST_SKIP() << "needs a private mount namespace (root): " << test::kNoPrivateTmp;
  ASSERT_FALSE(zero_copy::roudi_running()) << "this process's own /tmp holds no RouDi";
  std::optional<Roudi> roudi;  // ends after the modules that joined it
  auto src = plain_source_process();
  auto sink = module(kSink);
  auto& k = dynamic_cast<test::PlainSink&>(sink->kernel("sink").kernel());
  FlagArrivals arrivals(sink->kernel("sink").ports().find_input("flag")->buffer());
  ASSERT_TRUE(eventually(
      [&] {
        arrivals.take_new();
        return arrivals.through_dds() >= 10;
      },
      60s))
      << src->output();
  EXPECT_EQ(arrivals.zero_copy(), 0u);
  roudi.emplace();
  ASSERT_TRUE(eventually(
      [&] {
        arrivals.take_new();
        return arrivals.zero_copy() >= 50;
      },
      60s))
      << src->output() << roudi->output();
  sink->stop();
  arrivals.expect_one_switch_losing_nothing();
  expect_each_flag_once(k);
  const auto said = src->output();
  EXPECT_THAT(said, HasSubstr("its plain cues go through DDS only: no RouDi runs on this host"));
  EXPECT_THAT(said, HasSubstr("joined this host's RouDi, which runs now: 2 plain output(s) offered "
                              "in shared memory from here on"));
  std::cout << "flags through DDS " << arrivals.through_dds() << ", then zero-copy "
            << arrivals.zero_copy() << '\n';
}

// Pull inputs of the producer in an oscar-run child: each answer is the producer's chunk, read in
// place, and every query finds what the producer's ring would (the newest, at or before, first
// at or after a time still to come, the newest n).
TEST_F(ZeroCopyWiring, PullsAcrossProcessesAreAnsweredWithTheProducersChunksInPlace) {
  auto src = plain_source_process();
  ASSERT_TRUE(eventually([] { return offered_here("src/image", "oscar::PlainGvImage"); }, 30s))
      << src->output();
  auto sink = module(kImagePuller);
  auto& in = dynamic_cast<Input<PlainGvImage>&>(*sink->kernel("sink").ports().find_input("image"));
  EXPECT_EQ(in.buffer().pushed(), 0u) << "a pull input receives nothing unasked";
  const auto check = [](const Input<PlainGvImage>::Ptr& image) {
    EXPECT_TRUE(zero_copy::identify_chunk(image.get())) << "the producer's chunk, in place";
    EXPECT_TRUE(test::plain_image_complete(*image));
    EXPECT_EQ(test::plain_image_frame(*image), image->header().seq());
  };
  Input<PlainGvImage>::Ptr now;
  ASSERT_TRUE(eventually([&] { return (now = in.pull()) && now->header().seq() > 10; }, 30s))
      << src->output();
  check(now);
  const auto t = generation_stamp(now->header());
  const auto earlier = in.pull_at(t - 30'000'000);  // 1-2 cycles of 20 ms before
  ASSERT_TRUE(earlier);
  check(earlier);
  EXPECT_LT(earlier->header().seq(), now->header().seq());
  EXPECT_LE(generation_stamp(earlier->header()), t - 30'000'000);
  const auto later = in.pull_at(t + 50'000'000, PullQuery::kAtOrAfter, 2s);  // still to come
  ASSERT_TRUE(later) << "held until the producer published it";
  check(later);
  EXPECT_GE(generation_stamp(later->header()), t + 50'000'000);
  const auto newest = in.pull_latest(4);
  ASSERT_EQ(newest.size(), 4u) << "the producer's ring (depth 4) as the input's mirror holds it";
  for (std::size_t i = 0; i < newest.size(); ++i) {
    check(newest[i]);
    if (i > 0) {
      EXPECT_EQ(newest[i]->header().seq(), newest[i - 1]->header().seq() + 1);
    }
  }
  EXPECT_GE(in.buffer().pushed(), 4u) << "the answers land in the input's ring too";
}

// A pull input wired before its producer runs asks over DDS; once the producer, started later,
// offers its chunks, the input's pulls are answered from them in place.
TEST_F(ZeroCopyWiring, APullInputWhoseProducerStartsLaterReadsItsChunksOnceOffered) {
  auto sink = module(kImagePuller);
  auto& in = dynamic_cast<Input<PlainGvImage>&>(*sink->kernel("sink").ports().find_input("image"));
  auto src = plain_source_process();
  Input<PlainGvImage>::Ptr image;
  ASSERT_TRUE(eventually([&] { return (image = in.pull(200ms)) != nullptr; }, 30s))
      << src->output();
  ASSERT_TRUE(eventually(
      [&] {
        image = in.pull(200ms);
        return image && zero_copy::identify_chunk(image.get());
      },
      30s))
      << "answered in place once the producer offers its chunks";
  EXPECT_TRUE(test::plain_image_complete(*image));
  const auto newest = in.pull_latest(4);
  ASSERT_EQ(newest.size(), 4u);
  for (const auto& cue : newest) EXPECT_TRUE(zero_copy::identify_chunk(cue.get()));
}

// A pull input wired after its producer went quiet still finds the producer's last cues: the
// producer's publisher keeps them (up to 16) for a mirror that connects later.
TEST_F(ZeroCopyWiring, APullInputWiredAfterItsProducerWentQuietFindsItsLastCues) {
  auto src = test::run_module("src", {"-k", "bench_source:src", "-p", "src.type=PlainBool", "-p",
                                      "src.count=10", "-m", "continuous:10ms"});
  ASSERT_TRUE(eventually([] { return offered_here("src/out", "oscar::PlainBool"); }, 30s))
      << src->output();
  // Quiet: a subscriber that asks for no history gets nothing more.
  zero_copy::ChunkSubscriber quiet(zero_copy_topic_of("src/out"), "oscar::PlainBool");
  ASSERT_TRUE(eventually([&] { return quiet.subscribed(); }, 10s));
  ASSERT_TRUE(eventually([&] { return quiet.take(500ms) == nullptr; }, 30s)) << src->output();
  auto sink = module(R"(
name: late_puller
mode: deactivated
kernels:
  - type: test_plain_sink
    name: sink
    inputs: { flag: { source: src/out, transfer: pull }, image: src/image }
)");
  auto& in = dynamic_cast<Input<PlainBool>&>(*sink->kernel("sink").ports().find_input("flag"));
  std::vector<Input<PlainBool>::Ptr> cues;
  ASSERT_TRUE(eventually([&] { return (cues = in.pull_latest(16)).size() == 10; }, 10s))
      << cues.size() << " cues";
  for (std::size_t i = 0; i < cues.size(); ++i) {
    EXPECT_EQ(cues[i]->header().seq(), i + 1);
    EXPECT_TRUE(zero_copy::identify_chunk(cues[i].get())) << "in place";
  }
}

// With RouDi joined, an input whose cues cannot come zero-copy reads through DDS and says why.
TEST_F(ZeroCopyWiring, AnInputThatCannotGoZeroCopyReadsThroughDdsAndSaysWhy) {
  std::ostringstream said;
  auto capture = std::make_shared<spdlog::sinks::ostream_sink_mt>(said);
  spdlog::default_logger()->sinks().push_back(capture);
  auto m = module(R"(
name: mixed
mode: { continuous: 10ms }
kernels:
  - { type: test_plain_sink, name: sink, inputs: { flag: nobody/flag, image: nobody/image } }
  - { type: test_gv, name: gv, inputs: { in: cam/image } }
)");
  m->stop();
  std::erase(spdlog::default_logger()->sinks(), capture);
  EXPECT_THAT(said.str(), HasSubstr("cues of cam/image go serialized, not zero-copy: cue type "
                                    "oscar::GvImage is not plain"));
  EXPECT_THAT(said.str(), HasSubstr("cues of nobody/image go serialized, not zero-copy: no "
                                    "process of this host offers it in shared memory"));
}

}  // namespace
}  // namespace oscar
