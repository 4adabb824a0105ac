#pragma once
/// @file The producer end of a zero-copy channel: cues built in shared-memory chunks loaned from
/// RouDi and published without a copy (docs/zero_copy.md).

#include <cstddef>
#include <memory>
#include <new>
#include <string>

#include "zero_copy/plain_cue.hpp"

namespace oscar::zero_copy {

/// The most chunks a publisher keeps for subscribers that ask for its history (iceoryx 2.0's
/// MAX_PUBLISHER_HISTORY).
inline constexpr std::size_t kMaxChunkHistory = 16;

/// An iceoryx publisher of untyped chunks for one topic. Needs join_roudi() first.
class ChunkPublisher {
 public:
  /// Keeps the last `history` chunks it published (at most kMaxChunkHistory) for subscribers
  /// that ask for them when they connect.
  /// @throws std::invalid_argument if the topic or type name does not fit a service description,
  ///         or `history` is above kMaxChunkHistory.
  ChunkPublisher(const std::string& topic, const std::string& type_name, std::size_t history = 0);
  ~ChunkPublisher();
  ChunkPublisher(const ChunkPublisher&) = delete;
  ChunkPublisher& operator=(const ChunkPublisher&) = delete;

  /// A chunk for `bytes` of payload, or nullptr when RouDi's mempools have no chunk that size
  /// left (or none that big).
  void* loan(std::size_t bytes, std::size_t alignment);
  /// Hands a loaned chunk to every subscriber; the publisher no longer owns it.
  void publish(void* payload);
  /// Gives back a loaned chunk that is not to be published.
  void release(void* payload);
  /// True while at least one subscriber is connected.
  bool has_subscribers() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A typed publisher of plain cues: the producer fills the cue where it lies in the chunk.
template <PlainCue T>
class PlainPublisher {
 public:
  /// Gives an unpublished loan back to the publisher.
  struct ReturnLoan {
    ChunkPublisher* chunks = nullptr;
    void operator()(T* cue) const { chunks->release(cue); }
  };
  /// A cue under construction in a loaned chunk; published by publish(), else given back.
  using Loan = std::unique_ptr<T, ReturnLoan>;

  explicit PlainPublisher(const std::string& topic) : chunks_(topic, PlainCueTraits<T>::kName) {}

  /// A default-constructed cue in a fresh chunk; empty when RouDi's mempools are exhausted.
  Loan loan() {
    void* chunk = chunks_.loan(sizeof(T), alignof(T));
    return Loan(chunk ? new (chunk) T() : nullptr, ReturnLoan{&chunks_});
  }
  /// Publishes the loaned cue to every subscriber.
  void publish(Loan cue) { chunks_.publish(cue.release()); }
  bool has_subscribers() const { return chunks_.has_subscribers(); }

 private:
  ChunkPublisher chunks_;
};

}  // namespace oscar::zero_copy
