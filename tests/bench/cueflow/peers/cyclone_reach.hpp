#pragma once
// Where oscar-bench-cyclonedds may talk (its CYCLONEDDS_URI): the loopback interface, or for the
// remote constellation one test host's address with unicast discovery to the given peers. Never
// multicast, never another interface, whatever the environment says (docs/benchmarks.md).
#include <arpa/inet.h>

#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace oscar::bench {

struct Reach {
  std::string address;                 ///< "": the loopback interface
  std::vector<std::string> peers;      ///< unicast discovery to these (with an address)
  std::uint32_t udp_buffer_bytes = 0;  ///< asked for (the kernel may give less); 0: Cyclone's
};

inline bool is_ipv4(const std::string& s) {
  in_addr a{};
  return inet_pton(AF_INET, s.c_str(), &a) == 1;
}

/// What is wrong with `reach` as options, naming the option and the rule; "" if nothing.
inline std::string reach_error(const Reach& reach) {
  for (const auto& p : reach.peers) {
    if (!is_ipv4(p)) return fmt::format("--peer '{}': not an IPv4 address", p);
  }
  if (reach.address.empty()) {
    return reach.peers.empty() ? "" : "--peer goes with --address (without it: loopback only)";
  }
  if (!is_ipv4(reach.address)) {
    return fmt::format("--address '{}': not an IPv4 address", reach.address);
  }
  return reach.peers.empty() ? "--address needs --peer (where discovery looks, one per host)" : "";
}

/// The Cyclone DDS configuration for `reach` (XML, as CYCLONEDDS_URI takes it).
inline std::string cyclone_config(const Reach& reach) {
  std::string peers;
  for (const auto& p :
       reach.address.empty() ? std::vector<std::string>{"localhost"} : reach.peers) {
    peers += fmt::format("<Peer address=\"{}\"/>", p);
  }
  const auto interface = reach.address.empty()
                             ? std::string("<NetworkInterface name=\"lo\"/>")
                             : fmt::format("<NetworkInterface address=\"{}\"/>", reach.address);
  const auto buffers = reach.udp_buffer_bytes == 0
                           ? std::string()
                           : fmt::format(
                                 "<Internal><SocketReceiveBufferSize min=\"default\" max=\"{0}B\"/>"
                                 "<SocketSendBufferSize min=\"default\" max=\"{0}B\"/></Internal>",
                                 reach.udp_buffer_bytes);
  return fmt::format(
      "<CycloneDDS><Domain id=\"any\"><General><Interfaces>{}</Interfaces>"
      "<AllowMulticast>false</AllowMulticast></General><Discovery>"
      "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30"
      "</MaxAutoParticipantIndex><Peers>{}</Peers></Discovery>{}</Domain></CycloneDDS>",
      interface, peers, buffers);
}

}  // namespace oscar::bench
