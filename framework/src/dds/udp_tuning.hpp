#pragma once
// UDP transport settings of a participant (docs/network.md, "UDP between hosts"): the socket
// buffer size and the largest datagram. With the operating system's socket buffers (208 KiB) a
// 442 KB image overflows the receiver's buffer when it arrives in one burst; each lost datagram
// waits for a heartbeat and a NACK, and a reliable keep-last writer that is repairing one cue
// drops the ones behind it (`oscar bench cueflow`, remote rows).

#include <cstdint>
#include <string>

#include "oscar/network.hpp"

namespace oscar::internal {

struct UdpTuning {
  std::uint32_t buffer_bytes{};       ///< SO_SNDBUF and SO_RCVBUF; 0: the system's default
  std::uint32_t max_message_bytes{};  ///< largest datagram; 0: Fast DDS's 65500
};

/// The profile's `udp_buffer_bytes` and `udp_max_message_bytes`, each replaced by
/// $OSCAR_UDP_BUFFER_BYTES or $OSCAR_UDP_MAX_MESSAGE_BYTES where that is set (for experiments
/// and benchmarks; 0 meaning the system's or Fast DDS's default).
/// @throws std::invalid_argument naming the variable for a value out of udp_bytes()' range.
UdpTuning udp_tuning(const NetworkConfig& net);

/// A byte count of UDP setting `what` (e.g. "network.udp_buffer_bytes") as written: 0 or a
/// whole number of bytes in the setting's range (buffer 65536..1073741824, so never below a
/// datagram; message 1024..65500).
/// @throws std::invalid_argument naming `what`, the text and the range.
std::uint32_t udp_buffer_bytes(const std::string& what, const std::string& text);
std::uint32_t udp_max_message_bytes(const std::string& what, const std::string& text);

}  // namespace oscar::internal
