#pragma once
// Pulls answered from a ring buffer in this process: the producer's output ring buffer in a
// multi-core module, or what a harness fed. The answer also lands in the consumer's ring.

#include "oscar/input.hpp"

namespace oscar::internal {

class RingPullSource final : public PullSource {
 public:
  RingPullSource(const RingBuffer& producer, InputPort& consumer)
      : producer_(producer), consumer_(consumer) {}

  std::shared_future<std::shared_ptr<const void>> request(PullQuery query, Stamp t) override {
    std::optional<RingEntry> e;
    switch (query) {
      case PullQuery::kLatest:
        e = producer_.latest();
        break;
      case PullQuery::kAtOrBefore:
        e = producer_.at_or_before(t);
        break;
      case PullQuery::kNearest:
        e = producer_.nearest(t);
        break;
    }
    std::promise<std::shared_ptr<const void>> answer;
    if (e) {
      consumer_.buffer().push(e->cue, e->t, wall_now());
      answer.set_value(e->cue);
    } else {
      answer.set_value(nullptr);
    }
    return answer.get_future().share();
  }

  std::shared_future<CueBlock> request(const PullBlock& block) override {
    const auto entries = block.kind == PullBlock::Kind::kLatest
                             ? producer_.latest(block.n)
                             : producer_.range(block.t0, block.t1);
    CueBlock cues;
    cues.reserve(entries.size());
    for (const auto& e : entries) {
      consumer_.buffer().push(e.cue, e.t, wall_now());
      cues.push_back(e.cue);
    }
    std::promise<CueBlock> answer;
    answer.set_value(std::move(cues));
    return answer.get_future().share();
  }

 private:
  const RingBuffer& producer_;
  InputPort& consumer_;
};

}  // namespace oscar::internal
