// What an output does around a cue's generation stamp. A consumer woken on the producer's core
// runs only once the producer waits (docs/zero_copy.md, "Limits learned"), so the work that is
// no part of the cue's journey comes before the stamp.
#include <memory>

#include <gtest/gtest.h>

#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"

namespace oscar {
namespace {

TEST(OutputPort, CompletesTheHeaderBeforeItReadsTheClock) {
  OutputPort out("src", "out", cue_type_info<Bool>(), OutputOptions{});
  out.publish_erased(std::make_shared<Bool>());
  auto cue = std::make_shared<Bool>();
  const Bool* seen = cue.get();
  bool read = false;
  out.set_clock([&] {
    EXPECT_EQ(seen->header().seq(), 2u);
    EXPECT_EQ(seen->header().source(), "src/out");
    read = true;
    return Stamp{42};
  });
  out.publish_erased(std::move(cue));
  EXPECT_TRUE(read);
  EXPECT_EQ(out.buffer().latest()->t, 42);
}

TEST(OutputPort, FreesTheCueItsRingEvictsBeforeItStampsTheNext) {
  OutputPort out("src", "out", cue_type_info<Bool>(), OutputOptions{.depth = 2});
  auto first = std::make_shared<Bool>();
  const std::weak_ptr<Bool> first_held = first;
  out.publish_erased(std::move(first));
  out.publish_erased(std::make_shared<Bool>());
  ASSERT_FALSE(first_held.expired()) << "the ring holds it";
  bool read = false;
  out.set_clock([&] {
    EXPECT_TRUE(first_held.expired()) << "freed before the stamp";
    EXPECT_EQ(out.buffer().size(), 1u);
    read = true;
    return Stamp{42};
  });
  out.publish_erased(std::make_shared<Bool>());
  EXPECT_TRUE(read);
  EXPECT_EQ(out.buffer().size(), 2u);
  EXPECT_EQ(out.buffer().pushed(), 3u);
}

TEST(OutputPort, GivesItsRingAndItsInputsTheStampItCompletedTheHeaderWith) {
  OutputPort out("src", "out", cue_type_info<Bool>(), OutputOptions{});
  InputPort in("dst", "in", cue_type_info<Bool>(), InputOptions{});
  out.connect(&in);
  out.set_clock([] { return Stamp{42}; });
  out.publish_erased(std::make_shared<Bool>());
  EXPECT_EQ(out.buffer().latest()->t, 42);
  EXPECT_EQ(in.buffer().latest()->t, 42);

  auto stamped = std::make_shared<Bool>();
  append_stamp(stamped->header(), 7);  // a kernel's own generation stamp
  append_stamp(stamped->header(), 9);
  out.publish_erased(std::move(stamped));
  EXPECT_EQ(out.buffer().latest()->t, 7);
  EXPECT_EQ(in.buffer().latest()->t, 7);

  auto replayed = std::make_shared<Bool>();
  append_stamp(replayed->header(), 99);
  out.forward_erased(std::move(replayed));
  EXPECT_EQ(out.buffer().latest()->t, 99);
  EXPECT_EQ(in.buffer().latest()->t, 99);
}

}  // namespace
}  // namespace oscar
