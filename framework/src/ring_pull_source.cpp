#include "ring_pull_source.hpp"

namespace oscar::internal {

RingPullSource::RingPullSource(const RingBuffer& producer, InputPort& consumer, OutputPort* output)
    : producer_(producer),
      consumer_(consumer),
      output_(output),
      watcher_(consumer.kernel(), consumer.name() + " (held pulls)",
               output ? output->type() : consumer.type(), InputOptions{.depth = 1}),
      held_(producer) {}

RingPullSource::~RingPullSource() {
  // After this no publish reaches the held pulls; ~HeldPulls answers them with nothing.
  if (output_) output_->disconnect(&watcher_);
}

void RingPullSource::watch_output() {
  std::call_once(watching_, [this] {
    watcher_.set_arrival_hook([this] {
      if (auto e = watcher_.buffer().latest()) held_.arrived(*e);
    });
    output_->connect(&watcher_);
  });
}

std::shared_future<std::shared_ptr<const void>> RingPullSource::request(
    PullQuery query, Stamp t, std::chrono::nanoseconds wait) {
  auto answer = std::make_shared<std::promise<std::shared_ptr<const void>>>();
  auto future = answer->get_future().share();
  const auto deliver = [this, answer](std::optional<RingEntry> e) {
    if (e) consumer_.buffer().push(e->cue, e->t, wall_now());
    answer->set_value(e ? e->cue : nullptr);
  };
  switch (query) {
    case PullQuery::kLatest:
      deliver(producer_.latest());
      break;
    case PullQuery::kAtOrBefore:
      deliver(producer_.at_or_before(t));
      break;
    case PullQuery::kNearest:
      deliver(producer_.nearest(t));
      break;
    case PullQuery::kAtOrAfter:
      if (output_ && wait > std::chrono::nanoseconds::zero()) watch_output();
      // A harness's ring is not watched: the pull is answered from it at the end of the wait.
      held_.ask(consumer_.kernel() + "/" + consumer_.name(), t, wait, deliver);
      break;
  }
  return future;
}

std::shared_future<CueBlock> RingPullSource::request(const PullBlock& block) {
  const auto entries = block.kind == PullBlock::Kind::kLatest ? producer_.latest(block.n)
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

}  // namespace oscar::internal
