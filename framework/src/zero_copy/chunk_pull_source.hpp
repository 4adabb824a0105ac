#pragma once
/// @file Pull and prefetch on the zero-copy path (docs/zero_copy.md, "Pull and prefetch").

#include <string>

#include "oscar/input.hpp"
#include "oscar/output.hpp"
#include "ring_pull_source.hpp"
#include "zero_copy/chunk_feed.hpp"

namespace oscar::zero_copy {

/// The pulls of an input whose producer offers its chunks on this host, answered in this process:
/// a mirror of the producer's output ring, as deep as the input, holds the producer's own chunks
/// (those its publisher kept, up to 16, when the mirror connected, then each one as it is
/// published: a feed thread takes them), and the pulls read it as a pull of a producer in the
/// same module reads that producer's ring. No request goes to the producer and
/// no cue is copied: the answer is the chunk the producer filled. Needs join_roudi() first.
class ChunkPullSource final : public PullSource {
 public:
  /// `topic`: the producer's output (zero_copy_topic()), `source` its "<kernel>/<channel>".
  /// @throws std::invalid_argument for a topic iceoryx cannot take.
  ChunkPullSource(const std::string& topic, const std::string& source, InputPort& consumer);

  std::shared_future<std::shared_ptr<const void>> request(PullQuery query, Stamp t,
                                                          std::chrono::nanoseconds wait) override {
    return pulls_.request(query, t, wait);
  }
  std::shared_future<CueBlock> request(const PullBlock& block) override {
    return pulls_.request(block);
  }
  /// True once RouDi has connected the feed to the producer's output.
  bool subscribed() const { return feed_.subscribed(); }

 private:
  OutputPort mirror_;               // the producer's ring as this process sees it
  internal::RingPullSource pulls_;  // answers from mirror_; a held pull watches it
  ChunkFeed feed_;                  // last: stops before what it fills goes
};

}  // namespace oscar::zero_copy
