#pragma once
// Pulls answered from a ring buffer in this process: the producer's output ring buffer in a
// multi-core module, or what a harness fed. The answer also lands in the consumer's ring.

#include <mutex>

#include "held_pulls.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"

namespace oscar::internal {

class RingPullSource final : public PullSource {
 public:
  /// Answers from `producer`. A pull for a cue not there yet (PullQuery::kAtOrAfter) is held
  /// until `output` takes one: `output` owns `producer` and must outlive this source. Without an
  /// output (a harness's ring) such a pull is answered at the end of its wait, from the ring.
  RingPullSource(const RingBuffer& producer, InputPort& consumer, OutputPort* output = nullptr);
  /// Stops watching the output; held pulls are answered with nothing.
  ~RingPullSource() override;

  std::shared_future<std::shared_ptr<const void>> request(PullQuery query, Stamp t,
                                                          std::chrono::nanoseconds wait) override;
  std::shared_future<CueBlock> request(const PullBlock& block) override;
  /// Pulls held now, waiting for a cue.
  std::size_t held() const { return held_.held(); }

 private:
  void watch_output();  // once, before the first pull is held

  const RingBuffer& producer_;
  InputPort& consumer_;
  OutputPort* output_;
  // Connected to the output like a push input: its arrival hook, on the publishing thread,
  // answers the held pulls the new cue matches.
  InputPort watcher_;
  std::once_flag watching_;
  HeldPulls held_;  // declared last: destroyed (answering what is held) before the watcher
};

}  // namespace oscar::internal
