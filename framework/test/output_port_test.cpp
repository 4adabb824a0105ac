// What an output does around a cue's generation stamp. A consumer woken on the producer's core
// runs only once the producer waits (docs/zero_copy.md, "Limits learned"), so the work that is
// no part of the cue's journey comes before the stamp.
#include <memory>

#include <gtest/gtest.h>

#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
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

}  // namespace
}  // namespace oscar
