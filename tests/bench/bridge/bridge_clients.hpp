#pragma once
// Foxglove WebSocket clients for `oscar bench bridge`: each connects to the bridge with the
// protocol's subprotocol, subscribes to one topic's channel once it is advertised, and takes
// the delay of every message it is delivered: its arrival (system clock) minus the cue's first
// stamp (when its producer made it), read from the CDR payload.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace oscar::bench {

/// The first stamp of a cue's header (header.stamps[0], ns since the Unix epoch) in the CDR of a
/// cue whose first member is its header (`sequence<unsigned long long> stamps` first), or 0 if
/// the bytes are not little-endian plain CDR with at least one stamp.
std::uint64_t first_stamp(const std::uint8_t* cdr, std::size_t size);

struct ClientResult {
  std::vector<double> delays_us;  ///< one per CDR message, arrival minus the cue's first stamp
  /// The same messages' arrival minus their receive time in the frame header (when the bridge
  /// took them from DDS): the part of the delay after DDS, in the bridge and the socket.
  std::vector<double> after_dds_us;
  std::size_t messages = 0;  ///< every message after the warm-up (JSON side channels too)
  std::string error;         ///< why the client stopped early, or ""
};

/// Connects to ws://127.0.0.1:`port`, subscribes to each of `topics` once advertised and
/// records delays until `stop`; messages before `measure_from` (steady clock) are not counted
/// (the warm-up).
ClientResult run_client(int port, const std::vector<std::string>& topics,
                        std::chrono::steady_clock::time_point measure_from,
                        const std::atomic<bool>& stop);

}  // namespace oscar::bench
