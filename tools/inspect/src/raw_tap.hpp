#pragma once
// RawTap: subscribes to topics without knowing their types (the recorder's raw CDR type
// support, registered under the type discovery reports) and hands every sample's bytes, with
// its receive time, to a callback — what `oscar topics`, `echo` and `hz` listen with.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "oscar/dds_participant.hpp"

namespace oscar::inspect {

class RawTap {
 public:
  /// Called on a Fast DDS thread for every sample.
  using Fn = std::function<void(const std::string& topic, std::vector<std::uint8_t> bytes,
                                std::uint64_t receive_ns)>;
  RawTap(DdsParticipant& participant, Fn fn);
  ~RawTap();
  RawTap(const RawTap&) = delete;
  RawTap& operator=(const RawTap&) = delete;

  /// Subscribes to `topic` with the type and QoS of its discovered writer (best effort if the
  /// writer is; transient local if it is, so a last state is heard). Returns the type name, or
  /// "" if no writer of the topic has been discovered yet. Subscribing twice is a no-op.
  std::string subscribe(const std::string& topic);
  /// Stops reading `topic` (deletes its reader); a no-op if not subscribed. Samples already
  /// being handed over may still reach the callback while this returns.
  void unsubscribe(const std::string& topic);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Waits up to `timeout` for a writer of `topic` to be discovered; its type, or "".
std::string wait_for_writer(DdsParticipant& participant, const std::string& topic,
                            std::chrono::milliseconds timeout);

/// Nanoseconds since the epoch, now.
std::uint64_t now_ns();

}  // namespace oscar::inspect
