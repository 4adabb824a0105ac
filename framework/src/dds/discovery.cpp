#include "dds/discovery.hpp"

#include <unistd.h>

#include <algorithm>
#include <stdexcept>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fmt/format.h>

#include "dds/participant_identity.hpp"

namespace oscar {
namespace dds = eprosima::fastdds::dds;
using eprosima::fastdds::rtps::RemoteServerAttributes;
using eprosima::fastrtps::rtps::DiscoveryProtocol;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

int discovery_server_participant_id(int index) { return kParticipantIdsPerDomain - 1 - index; }

std::uint32_t discovery_server_port(int domain, int index) {
  return internal::metatraffic_unicast_port(domain, discovery_server_participant_id(index));
}

namespace internal {
namespace {

// How often clients ping their servers until they are matched, and servers go through what
// they learned (Fast DDS's default: 450 ms).
const eprosima::fastrtps::Duration_t kServerSyncPeriod(0, 50'000'000);

Locator_t udp_locator(const std::string& address, std::uint32_t port) {
  Locator_t l;
  IPLocator::setIPv4(l, address);
  l.port = port;
  return l;
}

// The participant ids claimed on `address` now (participant_identity.hpp), this one's included.
std::vector<int> claimed_ids(int domain, const std::string& address, int ids) {
  std::vector<int> claimed;
  const auto stem = fmt::format("{}/{}{}_", kClaimDir, claim_prefix(domain), address);
  for (int id = 0; id < ids; ++id) {
    if (access((stem + std::to_string(id)).c_str(), F_OK) == 0) claimed.push_back(id);
  }
  return claimed;
}

}  // namespace

int participant_ids(const NetworkConfig& net, int domain) {
  int ids = std::min(net.max_participants_per_host, kParticipantIdsPerDomain);
  if (net.discovery == Discovery::kServer) {
    ids = std::min(
        ids, discovery_server_participant_id(static_cast<int>(net.discovery_servers.size()) - 1));
  }
  while (ids > 0 && user_unicast_port(domain, ids - 1) > 65535) --ids;
  return ids;
}

RemoteServerAttributes remote_server(const std::string& address, int domain, int index) {
  RemoteServerAttributes server;
  eprosima::fastdds::rtps::get_server_client_default_guidPrefix(index, server.guidPrefix);
  server.metatrafficUnicastLocatorList.push_back(
      udp_locator(address, discovery_server_port(domain, index)));
  return server;
}

void configure_discovery(eprosima::fastrtps::rtps::BuiltinAttributes& builtin,
                         const NetworkConfig& net, int domain, DiscoveryScope scope) {
  auto& discovery = builtin.discovery_config;
  builtin.initialPeersList.clear();
  discovery.m_DiscoveryServers.clear();
  if (net.discovery == Discovery::kServer) {
    if (net.discovery_servers.empty()) {
      throw std::invalid_argument("network: discovery: server, but no discovery server address");
    }
    // A super client learns of every participant and endpoint, as with static peers (boot, the
    // registry and the tools need the whole graph), but from the servers alone: nobody
    // announces itself to every participant id of every host any more. A plain client learns
    // only of the participants it shares a topic with, and of their endpoints on those topics:
    // a module's participant does not parse, match or answer the rest of the system
    // (docs/network.md, "Discovery: static peers or a discovery server").
    discovery.discoveryProtocol = scope == DiscoveryScope::kSharedTopics
                                      ? DiscoveryProtocol::CLIENT
                                      : DiscoveryProtocol::SUPER_CLIENT;
    discovery.discoveryServer_client_syncperiod = kServerSyncPeriod;
    for (std::size_t i = 0; i < net.discovery_servers.size(); ++i) {
      discovery.m_DiscoveryServers.push_back(
          remote_server(net.discovery_servers[i], domain, static_cast<int>(i)));
    }
    return;
  }
  discovery.discoveryProtocol = DiscoveryProtocol::SIMPLE;
  const int ids = participant_ids(net, domain);
  for (const auto& peer : net.peers) {
    // On its own address a participant announces itself only to the ids claimed before its own
    // was: each one that comes later announces itself to it, and it answers. Announcing to all
    // 120 ids cost a system of a hundred modules on one host 120 sends per announcement and
    // participant (docs/network.md).
    const bool own =
        std::find(net.interfaces.begin(), net.interfaces.end(), peer) != net.interfaces.end();
    std::vector<int> targets;
    if (own) {
      targets = claimed_ids(domain, peer, ids);
    } else {
      for (int id = 0; id < ids; ++id) targets.push_back(id);
    }
    for (const int id : targets) {
      builtin.initialPeersList.push_back(udp_locator(peer, metatraffic_unicast_port(domain, id)));
    }
  }
}

dds::DomainParticipantQos discovery_server_qos(const NetworkConfig& net, int domain, int index) {
  if (index < 0 || index >= static_cast<int>(net.discovery_servers.size())) {
    throw std::invalid_argument(fmt::format("discovery server {}: the network names {} server(s)",
                                            index, net.discovery_servers.size()));
  }
  const auto& address = net.discovery_servers[static_cast<std::size_t>(index)];
  dds::DomainParticipantQos qos;
  qos.name(fmt::format("oscar-discovery-server-{}", index));
  auto& transport = qos.transport();
  transport.use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList = {address};
  transport.user_transports.push_back(udp);
  auto& wire = qos.wire_protocol();
  eprosima::fastdds::rtps::get_server_client_default_guidPrefix(index, wire.prefix);
  wire.participant_id = discovery_server_participant_id(index);
  auto& builtin = wire.builtin;
  builtin.discovery_config.discoveryProtocol = DiscoveryProtocol::SERVER;
  builtin.discovery_config.discoveryServer_client_syncperiod = kServerSyncPeriod;
  builtin.avoid_builtin_multicast = true;
  builtin.metatrafficMulticastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.push_back(
      udp_locator(address, discovery_server_port(domain, index)));
  wire.default_unicast_locator_list.push_back(
      udp_locator(address, user_unicast_port(domain, wire.participant_id)));
  // The servers know each other: a client that reached only one still reaches all the others.
  for (std::size_t i = 0; i < net.discovery_servers.size(); ++i) {
    if (static_cast<int>(i) == index) continue;
    builtin.discovery_config.m_DiscoveryServers.push_back(
        remote_server(net.discovery_servers[i], domain, static_cast<int>(i)));
  }
  // As every participant (participant.cpp): a vanished client is dropped after 3 s.
  builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(3, 0);
  builtin.discovery_config.leaseDuration_announcementperiod =
      eprosima::fastrtps::Duration_t(0, 200000000);
  return qos;
}

}  // namespace internal
}  // namespace oscar
