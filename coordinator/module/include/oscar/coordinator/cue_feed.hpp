#pragma once
/// @file CueFeed: an applet reads a module's cues (docs/coordinator.md, "Reading cues"): the
/// newest cue of one output, as it arrives over DDS. Applets decide from what the modules see
/// (a door sign found, a pose) as kernels do from their inputs, but they poll: the feed keeps the
/// newest cue and counts them; the applet looks at it in its step.

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "oscar/cue.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::coordinator {

/// The type-independent part, so an applet can own feeds of any type.
class CueFeedBase {
 public:
  virtual ~CueFeedBase() = default;
};

/// The newest cue of the output `address` ("kernel/channel"). The reader is best effort and
/// volatile, so it matches every producer (reliable or not, with or without history) and never
/// slows one down; a cue that arrives while the applet is between two looks replaces the older.
template <CueType T>
class CueFeed final : public CueFeedBase {
 public:
  CueFeed(DdsParticipant& participant, const std::string& address)
      : address_(address),
        reader_(participant, topics::cue(address),
                qos::cue_reader(OutputOptions{.depth = 1, .reliable = false}, 1,
                                Reliability::kBestEffort),
                [this](const T& cue, const auto&) { take(cue); }) {}

  const std::string& address() const { return address_; }
  /// The newest cue so far (a copy), or none before the first.
  std::optional<T> latest() const {
    std::lock_guard lock(mutex_);
    return latest_;
  }
  /// How many cues arrived so far: a caller that remembers it sees whether a new one came.
  std::uint64_t received() const {
    std::lock_guard lock(mutex_);
    return received_;
  }

 private:
  void take(const T& cue) {
    std::lock_guard lock(mutex_);
    latest_ = cue;
    ++received_;
  }

  std::string address_;
  mutable std::mutex mutex_;
  std::optional<T> latest_;
  std::uint64_t received_ = 0;
  // Last: destroyed first, so no DDS callback reaches the members above once they are gone.
  TopicReader<T, typename CueTraits<T>::PubSubType> reader_;
};

}  // namespace oscar::coordinator
