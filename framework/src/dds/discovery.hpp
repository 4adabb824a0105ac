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

/// What a client of the discovery servers learns from them.
enum class ServerClient {
  kSuper,  ///< every participant and endpoint (boot, the registry, the monitors, the tools)
  kPlain,  ///< only the participants and endpoints that share a topic with its own (modules)
};

/// Sets `builtin`'s discovery for `net`: initial peers (every usable participant id of every
/// peer) or the discovery servers this participant is a `client` of.
void configure_discovery(eprosima::fastrtps::rtps::BuiltinAttributes& builtin,
                         const NetworkConfig& net, int domain,
                         ServerClient client = ServerClient::kSuper);

/// Makes the next DdsParticipant this thread creates a `client` of the discovery servers, if
/// its network uses them; every later one is a super client again. Returns `net`, so that the
/// initializer that makes the participant says it: `participant_(domain, name,
/// next_participant_is(ServerClient::kPlain, net))`.
const NetworkConfig& next_participant_is(ServerClient client, const NetworkConfig& net);
/// What the participant being made is (DdsParticipant's constructor): what
/// next_participant_is() said, or kSuper; resets it to kSuper.
ServerClient take_next_participant_kind();

/// The remote-server entry for discovery server `index` of `domain` on `address`: its GUID
/// prefix (Fast DDS's default for server `index`) and its discovery locator.
eprosima::fastdds::rtps::RemoteServerAttributes remote_server(const std::string& address,
                                                              int domain, int index);

/// The QoS of discovery server `index` of `net` on `domain`: UDP on its address only, its
/// well-known locator, the other server (if any) as a peer server.
eprosima::fastdds::dds::DomainParticipantQos discovery_server_qos(const NetworkConfig& net,
                                                                  int domain, int index);

}  // namespace oscar::internal
