#pragma once
/// @file A push input fed by the zero-copy path (docs/zero_copy.md, "Wiring into the ports").

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "oscar/input.hpp"
#include "zero_copy/chunk_subscriber.hpp"

namespace oscar::zero_copy {

/// Subscribes to an output's chunks on this host and delivers each where it lies, on a thread of
/// its own: to a push input, whose ring buffer then holds the producer's chunks, or to any sink.
/// Needs join_roudi() first.
class ChunkFeed {
 public:
  using Sink = std::function<void(std::shared_ptr<const void> cue)>;

  /// `topic`: the iceoryx topic of the producer's output (zero_copy_topic()); `type`: its cue
  /// type. Up to the input's depth of chunks wait to be delivered. A `held` feed delivers nothing
  /// until hand_over(): it takes over from a DDS reader of the same output.
  /// @throws std::invalid_argument for a topic iceoryx cannot take.
  ChunkFeed(const std::string& topic, InputPort& input, const CueTypeInfo& type, bool held = false);
  /// Delivers to `sink` instead, up to `capacity` chunks waiting, first up to `history` the
  /// producer published before (ChunkSubscriber); `name` says whose feed it is in the log.
  ChunkFeed(const std::string& topic, const CueTypeInfo& type, std::size_t capacity,
            std::size_t history, Sink sink, std::string name, bool held = false);
  /// Delivers nothing more; returns once a delivery under way is done.
  ~ChunkFeed();
  ChunkFeed(const ChunkFeed&) = delete;
  ChunkFeed& operator=(const ChunkFeed&) = delete;

  /// True once RouDi has connected it to the producer's output: each cue published from then on
  /// reaches it (iceoryx keeps none from before).
  bool subscribed() const { return chunks_.subscribed(); }
  /// The seq of the oldest cue a held feed holds (it holds up to the input's depth, the newest).
  std::optional<std::uint64_t> first_held() const;
  /// Starts a held feed. The cues it holds that the reader it replaces delivered already (seq up
  /// to `delivered_through`, the input's newest) are dropped, so that the input gets each cue
  /// once; a cue of a restarted producer (a seq far below) is not.
  void hand_over(std::optional<std::uint64_t> delivered_through);

 private:
  void deliver(std::stop_token stop);
  void deliver_one(std::shared_ptr<const void> cue);
  std::uint64_t seq_of(const void* cue) const;

  const Sink sink_;
  const std::string name_;  // "input <kernel>/<name>" or the like, for the log
  const CueTypeInfo& type_;
  std::string topic_;
  const std::size_t capacity_;
  ChunkSubscriber chunks_;
  mutable std::mutex mutex_;
  bool held_;                                          // under mutex_
  std::deque<std::shared_ptr<const void>> held_cues_;  // under mutex_, while held_
  std::optional<std::uint64_t>
      delivered_through_;  // under mutex_; cleared by the first cue past it
  std::jthread thread_;    // last: stopped and joined first
};

}  // namespace oscar::zero_copy
