#pragma once
/// @file Where a participant may send and listen (docs/network.md).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace oscar {

/// Who a participant authenticates as under DDS Security (docs/security.md): an identity of the
/// system's keystore, whose certificate, key and signed permissions it loads.
struct ParticipantSecurity {
  std::string keystore;  ///< the keystore folder (`oscar security init`)
  std::string identity;  ///< e.g. "registry", "monitor.h1", "module.camera", "operator"
};

/// The transport profile of a DDS participant. The default confines it to the loopback
/// interface: UDP on 127.0.0.1 with unicast discovery to localhost, plus shared memory; no
/// multicast, no other interface. A system file may name other interfaces and peers.
struct NetworkConfig {
  std::vector<std::string> interfaces{"127.0.0.1"};  ///< IPv4 addresses UDP may use
  std::vector<std::string> peers{"127.0.0.1"};       ///< hosts discovery announces itself to
  bool shared_memory = true;
  std::uint32_t shm_segment_bytes = 8u << 20;  ///< must hold the largest cues in flight
  int max_participants_per_host = 32;          ///< participant ids probed per peer
  /// DDS Security's builtin plugins with this identity; none: a plain participant.
  std::optional<ParticipantSecurity> security;

  /// Reads a `network:` map (interfaces, peers, shared_memory, shm_segment_bytes).
  /// @throws std::invalid_argument on unknown keys or non-IPv4 addresses.
  static NetworkConfig from_yaml(const YAML::Node& node);
  /// The profile of a process on `host` of a system file: the file's `network:` if given, else
  /// the loopback default; a host with an `address:` (a test host in a network namespace) uses
  /// that address and announces itself to the addresses of all the system's hosts.
  static NetworkConfig for_host(const YAML::Node& system, const std::string& host);
};

/// The domain id from $OSCAR_DOMAIN, else `fallback`.
int domain_from_env(int fallback);

/// Sets Fast DDS's own log level from $OSCAR_DDS_LOG: `error` (Fast DDS's default), `warning`
/// or `info` (the latter only in Fast DDS debug builds). Every DdsParticipant applies it.
/// @throws std::invalid_argument for any other value.
void dds_log_level_from_env();

}  // namespace oscar
