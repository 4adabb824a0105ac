#pragma once
// UDP transport settings of a participant (docs/network.md, "UDP between hosts"): the socket
// buffer size and the largest datagram, from the environment. With the operating system's
// socket buffers (208 KiB) a 442 KB image overflows the receiver's buffer when it arrives in one
// burst; each lost datagram waits for a heartbeat and a NACK, and a reliable keep-last writer
// that is repairing one cue drops the ones behind it (`oscar bench cueflow`, remote rows).

#include <cstdint>

namespace oscar::internal {

struct UdpTuning {
  /// SO_SNDBUF and SO_RCVBUF (the kernel caps them at net.core.{w,r}mem_max); 0: the system's
  /// default.
  std::uint32_t buffer_bytes = 4u << 20;
  std::uint32_t max_message_bytes = 0;  ///< largest datagram; 0: Fast DDS's 65500
};

/// UdpTuning with $OSCAR_UDP_BUFFER_BYTES and $OSCAR_UDP_MAX_MESSAGE_BYTES where set (0 meaning
/// the system's or Fast DDS's default).
/// @throws std::invalid_argument naming the variable for a value that is not 0 or a whole number
/// of bytes in range (buffer 65536..1073741824, so never below a datagram; message 1024..65500).
UdpTuning udp_tuning_from_env();

}  // namespace oscar::internal
