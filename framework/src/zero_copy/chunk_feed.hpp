#pragma once
/// @file A push input fed by the zero-copy path (docs/zero_copy.md, "Wiring into the ports").

#include <memory>
#include <string>
#include <thread>

#include "oscar/input.hpp"
#include "zero_copy/chunk_subscriber.hpp"

namespace oscar::zero_copy {

/// Subscribes to an output's chunks on this host and delivers each to `input` where it lies, on a
/// thread of its own: the input's ring buffer holds the producer's chunks. Needs join_roudi()
/// first.
class ChunkFeed {
 public:
  /// `topic`: the iceoryx topic of the producer's output (zero_copy_topic()); `type`: its cue
  /// type. Up to the input's depth of chunks wait to be delivered.
  /// @throws std::invalid_argument for a topic iceoryx cannot take.
  ChunkFeed(const std::string& topic, InputPort& input, const CueTypeInfo& type);
  /// Delivers nothing more; returns once a delivery under way is done.
  ~ChunkFeed();
  ChunkFeed(const ChunkFeed&) = delete;
  ChunkFeed& operator=(const ChunkFeed&) = delete;

 private:
  void deliver(std::stop_token stop);

  InputPort& input_;
  const CueTypeInfo& type_;
  std::string topic_;
  ChunkSubscriber chunks_;
  std::jthread thread_;  // last: stopped and joined first
};

}  // namespace oscar::zero_copy
