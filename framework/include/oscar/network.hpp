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

/// Participant ids one domain has on one address: RTPS gives a domain 250 ports (spec 9.6.1.1)
/// and each participant two of them, from offset 10, so ids 0-119 stay in their domain's range.
inline constexpr int kParticipantIdsPerDomain = 120;
/// Participant ids a system of several hosts keeps free on each host beyond its modules there
/// (NetworkConfig::for_host): the monitor, boot, the registry, two discovery servers, a hung
/// module's successor, and tools (oscar ps, echo, record, the bridge) run at once.
inline constexpr int kParticipantsBesideModules = 16;

/// How the participants of a system find each other (docs/network.md).
enum class Discovery {
  kStaticPeers,  ///< each announces itself to every participant id of every peer (Fast DDS SIMPLE)
  kServer,       ///< each is a client of the discovery servers `oscar boot` starts
};

/// What a participant learns of from the discovery servers (docs/network.md): the whole system
/// (boot, the registry, the monitors, the tools: Fast DDS's SUPER_CLIENT) or only the
/// participants and endpoints that share a topic with its own (a module: a plain CLIENT, which
/// does not parse, match or answer the rest). With static peers every participant learns of all.
enum class DiscoveryScope { kWholeSystem, kSharedTopics };

/// The transport profile of a DDS participant. The default confines it to the loopback
/// interface: UDP on 127.0.0.1 with unicast discovery to localhost, plus shared memory; no
/// multicast, no other interface. A system file may name other interfaces and peers, or use
/// discovery servers.
struct NetworkConfig {
  std::vector<std::string> interfaces{"127.0.0.1"};  ///< IPv4 addresses UDP may use
  std::vector<std::string> peers{"127.0.0.1"};       ///< hosts discovery announces itself to
  bool shared_memory = true;
  /// Each participant's shared-memory segment: it holds what the participant sends until every
  /// reader on the host took it. Unset: shm_segment_bytes_for() picks by what it sends. Fast DDS
  /// writes the whole segment when the participant starts (8 MiB: about 8 ms of CPU), and it
  /// stays in /dev/shm while the participant lives.
  std::optional<std::uint32_t> shm_segment_bytes;
  /// UDP send and receive socket buffers: room for a 442 KB image in one burst (the kernel caps
  /// them at net.core.{w,r}mem_max); 0: the system's default.
  std::uint32_t udp_buffer_bytes = 4u << 20;
  /// The largest UDP datagram; larger samples go in fragments of it. 0: Fast DDS's 65500.
  std::uint32_t udp_max_message_bytes = 0;
  /// Participant ids taken and probed per address (at most kParticipantIdsPerDomain; a system
  /// of several hosts: its busiest host's modules and kParticipantsBesideModules).
  int max_participants_per_host = kParticipantIdsPerDomain;
  Discovery discovery = Discovery::kStaticPeers;
  /// kServer: the address of each discovery server, one or two (then either one suffices); the
  /// i-th listens on discovery_server_port(domain, i).
  std::vector<std::string> discovery_servers;
  /// DDS Security's builtin plugins with this identity; none: a plain participant.
  std::optional<ParticipantSecurity> security;

  /// Reads a `network:` map (interfaces, peers, shared_memory, shm_segment_bytes,
  /// udp_buffer_bytes, udp_max_message_bytes, max_participants_per_host, discovery,
  /// discovery_servers) over `base`.
  /// @throws std::invalid_argument on unknown keys, bad values or non-IPv4 addresses.
  static NetworkConfig from_yaml(const YAML::Node& node, NetworkConfig base);
  /// ... over the loopback default.
  static NetworkConfig from_yaml(const YAML::Node& node);
  /// The profile of a process on `host` of a system file: a host with an `address:` (a test host
  /// in a network namespace) uses that address and announces itself to the addresses of all the
  /// system's hosts, and to as many participant ids on each as the file puts on its busiest host
  /// (its modules there, the coordinator and its applets, kParticipantsBesideModules), else
  /// the loopback default; the file's `network:` keys override that.
  /// Discovery servers default to the address of the system's local host (where boot runs).
  static NetworkConfig for_host(const YAML::Node& system, const std::string& host);
};

/// The shared-memory segment of a participant that publishes cues: room for the largest (a
/// 442 KB image goes in fragments of 64 KB) while the slowest reader of the host catches up.
inline constexpr std::uint32_t kCueShmSegmentBytes = 8u << 20;
/// ... and of one that publishes none (only its state, log lines, replies).
inline constexpr std::uint32_t kQuietShmSegmentBytes = 1u << 20;

/// The segment of a participant with `network`: its shm_segment_bytes where set, else by
/// whether it publishes cues.
std::uint32_t shm_segment_bytes_for(const NetworkConfig& network, bool publishes_cues);

/// The participant id discovery server `index` (0 or 1) of a domain takes on its address: the
/// highest ones, which clients, taking the lowest free id, reach last.
int discovery_server_participant_id(int index);
/// The UDP port discovery server `index` of `domain` listens on (its id's discovery port).
std::uint32_t discovery_server_port(int domain, int index);

/// The domain id from $OSCAR_DOMAIN, else `fallback`.
int domain_from_env(int fallback);

/// The environment variable `oscar boot` sets for every process of the system it boots: one
/// value per boot ("<system>@<host>:<boot pid>:<start ms>"), which each DdsParticipant shows
/// discovery (DdsParticipant::DiscoveredParticipant::system_instance).
inline constexpr const char* kSystemInstanceEnv = "OSCAR_SYSTEM_INSTANCE";

/// $OSCAR_SYSTEM_INSTANCE, "" if unset: the booted system this process belongs to.
std::string system_instance_from_env();

/// Sets Fast DDS's own log level from $OSCAR_DDS_LOG: `error` (Fast DDS's default), `warning`
/// or `info` (the latter only in Fast DDS debug builds). Every DdsParticipant applies it.
/// @throws std::invalid_argument for any other value.
void dds_log_level_from_env();

}  // namespace oscar
