// Plain cue types as any kernel's cue types (docs/zero_copy.md): published and received in one
// process through the harness and across processes over DDS (serialized), headers completed by
// the frame, every pixel arriving; an output whose address a plain header cannot hold refused.
#include <chrono>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/harness.hpp"
#include "oscar/module.hpp"
#include "oscar/testing/eventually.hpp"
#include "plain_kernels.hpp"
#include "process.hpp"  // tests/common

namespace oscar {
namespace {
using namespace std::chrono_literals;
using testing::HasSubstr;

TEST(PlainCueHarness, APlainSourcesCuesCarryTheFramesHeaderAndTheirWholeImage) {
  KernelHarness h("test_plain_source");
  for (int i = 0; i < 3; ++i) {
    h.step();
    h.advance(10ms);
  }
  const auto images = h.take<PlainGvImage>("image");
  const auto flags = h.take<PlainBool>("flag");
  ASSERT_EQ(images.size(), 3u);
  ASSERT_EQ(flags.size(), 3u);
  const Stamp start = 1'000'000'000;  // the harness's first time
  for (std::size_t i = 0; i < 3; ++i) {
    const auto header = cue_type_info<PlainGvImage>().header.read(images[i].get());
    EXPECT_EQ(header.seq(), i + 1);
    EXPECT_EQ(header.source(), "kernel_under_test/image");
    EXPECT_EQ(header.stamps(),
              (std::vector<std::uint64_t>{static_cast<std::uint64_t>(start + 10'000'000 * i)}));
    EXPECT_TRUE(test::plain_image_complete(*images[i]));
    EXPECT_EQ(test::plain_image_frame(*images[i]), i + 1);
    EXPECT_EQ(source_of(flags[i]->header()), "kernel_under_test/flag");
    EXPECT_EQ(flags[i]->header().seq(), i + 1);
    EXPECT_EQ(flags[i]->value(), i % 2 == 0);
  }
}

// Output::loan() without the zero-copy path: heap memory, published as it is (no copy).
TEST(PlainCueHarness, ALoanedCueIsPublishedWhereTheKernelFilledIt) {
  KernelHarness h("test_plain_source");
  h.step();
  const auto images = h.take<PlainGvImage>("image");
  ASSERT_EQ(images.size(), 1u);
  EXPECT_EQ(images[0].get(), dynamic_cast<test::PlainSource&>(h.kernel()).last_image());
  EXPECT_TRUE(test::plain_image_complete(*images[0]));
}

TEST(PlainCueHarness, APlainSinkGetsFedCuesStampedWithTheHarnessTimeIfUnstamped) {
  KernelHarness h("test_plain_sink");
  auto image = std::make_unique<PlainGvImage>();
  test::fill_plain_image(*image, 5);
  h.feed("image", *image);
  append_stamp(image->header(), 77);
  h.feed("image", *image);
  PlainBool flag;
  flag.value(true);
  h.feed("flag", flag);
  h.step();
  auto& sink = dynamic_cast<test::PlainSink&>(h.kernel());
  const auto images = sink.images();
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0].header.stamps(), (std::vector<std::uint64_t>{1'000'000'000}));
  EXPECT_EQ(images[1].header.stamps(), (std::vector<std::uint64_t>{77}));
  EXPECT_TRUE(images[1].image_complete);
  EXPECT_EQ(images[1].frame, 5u);
  // The input's ring orders cues by their generation stamp, read through the plain header.
  EXPECT_EQ(h.instance().ports().find_input("image")->buffer().latest()->t, 77);
  ASSERT_EQ(sink.flags().size(), 1u);
  EXPECT_TRUE(sink.flags()[0].value);
}

TEST(PlainCueHarness, AnOutputWhoseAddressAPlainHeaderCannotHoldIsRefusedWhenDeclared) {
  // "<kernel>/image": 57 + 6 = 63 characters fit, one more does not.
  KernelHarness fits("test_plain_source", {}, std::string(57, 'k'));
  fits.step();
  EXPECT_EQ(fits.take<PlainGvImage>("image").at(0)->header().source()[62], 'e');
  EXPECT_THAT([] { KernelHarness("test_plain_source", {}, std::string(58, 'k')); },
              testing::ThrowsMessage<std::invalid_argument>(
                  AllOf(HasSubstr("output '" + std::string(58, 'k') + "/image'"),
                        HasSubstr("oscar::PlainGvImage"), HasSubstr("has 64 characters"),
                        HasSubstr("a source of at most 63"))));
}

// The sink in this process, the source in an oscar-run child that loads the test kernels'
// plugin: the cues cross processes over DDS, serialized.
TEST(PlainCueFlow, PlainImagesAndBoolsCrossProcessesWithTheirHeadersAndEveryPixel) {
  auto sink = std::make_unique<Module>(ModuleSpec::from_yaml(YAML::Load(R"(
name: plain_sink
mode: { continuous: 10ms }
kernels:
  - { type: test_plain_sink, name: sink, inputs: { flag: src/flag, image: src/image } }
)"),
                                                             "test"),
                                       plugin_search_path());
  sink->start(test::test_domain());
  auto src =
      test::run_module("plain_src", {"--plugin",
                                     test::build_dir() + "/lib/oscar/test_plugins/"
                                                         "liboscar_kernel_test_plain.so",
                                     "-k", "test_plain_source:src", "-m", "continuous:20ms"});
  auto& k = dynamic_cast<test::PlainSink&>(sink->kernel("sink").kernel());
  ASSERT_TRUE(eventually([&] { return k.images().size() >= 20 && k.flags().size() >= 20; }, 60s))
      << src->output();
  sink->stop();
  const auto images = k.images();
  for (std::size_t i = 0; i < images.size(); ++i) {
    const auto& h = images[i].header;
    EXPECT_EQ(h.source(), "src/image");
    ASSERT_EQ(h.stamps().size(), 1u) << "the generation stamp only";
    EXPECT_GT(h.stamps()[0], 1'700'000'000'000'000'000ull) << "a wall-clock time";
    EXPECT_TRUE(images[i].image_complete) << "seq " << h.seq();
    EXPECT_EQ(images[i].frame, h.seq()) << "the header belongs to its image";
    if (i > 0) {
      EXPECT_GT(h.seq(), images[i - 1].header.seq());
    }
  }
  const auto flags = k.flags();
  for (std::size_t i = 0; i < flags.size(); ++i) {
    EXPECT_EQ(flags[i].header.source(), "src/flag");
    EXPECT_EQ(flags[i].value, flags[i].header.seq() % 2 == 1) << "seq " << flags[i].header.seq();
    if (i > 0) {
      EXPECT_EQ(flags[i].header.seq(), flags[i - 1].header.seq() + 1) << "reliable";
    }
  }
}

}  // namespace
}  // namespace oscar
