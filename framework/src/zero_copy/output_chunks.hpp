#pragma once
/// @file An output's cues on the zero-copy path (docs/zero_copy.md, "Wiring into the ports").

#include <memory>
#include <string>

#include "oscar/output.hpp"
#include "zero_copy/chunk_subscriber.hpp"

namespace oscar::zero_copy {

/// Cues of one output in chunks loaned from RouDi, published to the host's other processes. A
/// subscriber of the output's own takes each chunk back as soon as it is published (iceoryx lets a
/// publisher no longer touch a published chunk), so the output's ring, its in-process inputs and
/// its DDS writer read the very chunk the other processes read. Needs join_roudi() first.
class OutputChunks final : public CueChunks {
 public:
  /// `topic`: the iceoryx topic (zero_copy_topic()). The output's ring holds its depth in chunks:
  /// RouDi's pools must have them. Waits up to a second for RouDi to connect the output's own
  /// subscriber. Its publisher keeps the last `history` chunks (those the ring holds anyway) for
  /// a consumer's pulls that start then (ChunkPullSource).
  /// @throws std::invalid_argument for a type that is not plain, or a topic iceoryx cannot take.
  OutputChunks(const std::string& topic, const CueTypeInfo& type, std::size_t history = 0);
  ~OutputChunks() override;

  std::shared_ptr<void> loan() override;
  std::shared_ptr<const void> publish(std::shared_ptr<const void> cue) override;

 private:
  struct Publisher;  // shared with every loan, which gives its chunk back on any thread
  struct ReturnLoan;
  std::shared_ptr<Publisher> publisher_;
  ChunkSubscriber own_;
  const CueTypeInfo& type_;
  std::string topic_;
  bool own_subscribed_ = false;  // under the publisher's mutex, as exhausted_said_
  bool exhausted_said_ = false;
};

}  // namespace oscar::zero_copy
