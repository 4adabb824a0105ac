#pragma once
// Internal: how a participant finds the others (docs/network.md): static peers (Fast DDS's
// SIMPLE discovery, announced to every participant id of every peer) or discovery servers.

#include <fastdds/rtps/attributes/RTPSParticipantAttributes.h>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "oscar/network.hpp"

namespace oscar::internal {

/// How many participant ids (0, 1, ...) a participant of `domain` may take on its address and,
/// with static peers, announces itself to on each peer: `max_participants_per_host`, less the
/// ids discovery servers take, less ids whose ports would not fit in 16 bits.
int participant_ids(const NetworkConfig& net, int domain);

/// Sets `builtin`'s discovery for `net`: initial peers (every usable participant id of every
/// peer) or the discovery servers, learning of what `scope` says.
void configure_discovery(eprosima::fastrtps::rtps::BuiltinAttributes& builtin,
                         const NetworkConfig& net, int domain,
                         DiscoveryScope scope = DiscoveryScope::kWholeSystem);

/// The remote-server entry for discovery server `index` of `domain` on `address`: its GUID
/// prefix (Fast DDS's default for server `index`) and its discovery locator.
eprosima::fastdds::rtps::RemoteServerAttributes remote_server(const std::string& address,
                                                              int domain, int index);

/// The QoS of discovery server `index` of `net` on `domain`: UDP on its address only, its
/// well-known locator, the other server (if any) as a peer server.
eprosima::fastdds::dds::DomainParticipantQos discovery_server_qos(const NetworkConfig& net,
                                                                  int domain, int index);

}  // namespace oscar::internal
