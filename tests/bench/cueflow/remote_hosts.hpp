#pragma once
// The remote constellation of `oscar bench cueflow`: producer and consumer on two test hosts in
// network namespaces (tests/netns/test_hosts.hpp), UDP between them over veth and a bridge, no
// shared memory. Namespaces share the machine's clocks, so arrival minus stamp stays valid.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace oscar::test {
class TestHosts;
}

namespace oscar::bench {

/// What crossed into a test host: the received counters of its interfaces other than loopback.
struct LinkCounters {
  std::uint64_t bytes = 0, packets = 0;
};

/// UDP settings for the participants of the remote constellation, given to both sides as
/// OSCAR_UDP_BUFFER_BYTES and OSCAR_UDP_MAX_MESSAGE_BYTES (docs/network.md); none: OSCAR's.
struct UdpSettings {
  std::optional<std::uint32_t> buffer_bytes, max_message_bytes;
};

class RemoteHosts {
 public:
  /// Why two test hosts cannot be made here (not root, no network namespaces), or "".
  static std::string unavailable();
  /// Hosts 1 (producer) and 2 (consumer); removed again, with what runs in them, on destruction.
  explicit RemoteHosts(UdpSettings udp);
  ~RemoteHosts();
  RemoteHosts(const RemoteHosts&) = delete;
  RemoteHosts& operator=(const RemoteHosts&) = delete;

  /// argv prefix running a program on host `i` (1 or 2) with the UDP settings in its environment.
  std::vector<std::string> on(int i) const;
  /// The `network:` map of a participant on host `i`: UDP on its test address, discovery to
  /// both hosts, no shared memory (shared memory would work across network namespaces on one
  /// machine, and the constellation would not be remote).
  std::string network(int i) const;
  /// The test address of host `i`.
  std::string address(int i) const;
  /// The UDP socket buffer size both sides ask for (OSCAR's 4 MiB unless the settings say).
  std::uint32_t udp_buffer_bytes() const { return udp_.buffer_bytes.value_or(4u << 20); }
  /// Received on host `i` so far.
  LinkCounters received(int i) const;

 private:
  UdpSettings udp_;
  std::unique_ptr<test::TestHosts> hosts_;
};

}  // namespace oscar::bench
