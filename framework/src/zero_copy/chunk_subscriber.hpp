#pragma once
/// @file The consumer end of a zero-copy channel: cues read in place, in the chunks the producer
/// wrote them in (docs/zero_copy.md).

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>

#include "zero_copy/plain_cue.hpp"

namespace oscar::zero_copy {

/// An iceoryx subscriber of untyped chunks for one topic. Needs join_roudi() first.
class ChunkSubscriber {
 public:
  /// Keeps up to `queue_capacity` received chunks not yet taken (the oldest go first). Asks each
  /// publisher it connects to for up to `history` chunks it published before (those it keeps).
  /// @throws std::invalid_argument if the topic or type name does not fit a service description.
  ChunkSubscriber(const std::string& topic, const std::string& type_name,
                  std::size_t queue_capacity = 16, std::size_t history = 0);
  ~ChunkSubscriber();
  ChunkSubscriber(const ChunkSubscriber&) = delete;
  ChunkSubscriber& operator=(const ChunkSubscriber&) = delete;

  /// The oldest chunk received and not yet taken, waiting up to `timeout`; nullptr if none came.
  /// The pointer is the payload inside the shared chunk: the chunk goes back to RouDi when the
  /// last copy of the pointer is gone (on any thread; the subscriber's state lives until then).
  /// @throws std::runtime_error if this process holds too many chunks of the topic at once
  ///         (iceoryx's MAX_CHUNKS_HELD_PER_SUBSCRIBER_SIMULTANEOUSLY).
  std::shared_ptr<const void> take(std::chrono::nanoseconds timeout);
  /// True once RouDi has connected it to the topic's publishers (iceoryx subscribes
  /// asynchronously).
  bool subscribed() const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

/// A typed subscriber of plain cues.
template <PlainCue T>
class PlainSubscriber {
 public:
  explicit PlainSubscriber(const std::string& topic, std::size_t queue_capacity = 16)
      : chunks_(topic, PlainCueTraits<T>::kName, queue_capacity) {}
  /// The oldest cue not yet taken, in place in the producer's chunk; nullptr if none came.
  std::shared_ptr<const T> take(std::chrono::nanoseconds timeout) {
    return std::static_pointer_cast<const T>(chunks_.take(timeout));
  }

 private:
  ChunkSubscriber chunks_;
};

}  // namespace oscar::zero_copy
