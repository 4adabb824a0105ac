// The discovery part of a participant's QoS, for static peers and for discovery servers
// (docs/network.md), and the network profile's discovery keys.
#include "dds/discovery.hpp"  // framework/src

#include <unistd.h>

#include <algorithm>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fastrtps/utils/IPLocator.h>

#include <oscar/configPubSubTypes.h>
#include "dds/participant_identity.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/discovery_server.hpp"
#include "oscar/testing/booted_system.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "process.hpp"  // tests/common

namespace oscar {
namespace {
using eprosima::fastrtps::rtps::BuiltinAttributes;
using eprosima::fastrtps::rtps::DiscoveryProtocol;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

std::string address_of(const Locator_t& l) { return IPLocator::ip_to_string(l); }

TEST(StaticPeers, AnnounceToEveryParticipantIdOfEveryPeerAndToNoServer) {
  NetworkConfig net;
  net.peers = {"10.77.0.1", "10.77.0.2"};
  BuiltinAttributes builtin;
  internal::configure_discovery(builtin, net, 7);
  EXPECT_EQ(builtin.discovery_config.discoveryProtocol, DiscoveryProtocol::SIMPLE);
  EXPECT_TRUE(builtin.discovery_config.m_DiscoveryServers.empty());
  ASSERT_EQ(builtin.initialPeersList.size(), 2u * kParticipantIdsPerDomain);
  const auto first = *builtin.initialPeersList.begin();
  EXPECT_EQ(address_of(first), "10.77.0.1");
  EXPECT_EQ(first.port, 7400u + 250 * 7 + 10);
  std::uint32_t highest = 0;
  for (const auto& l : builtin.initialPeersList) highest = std::max(highest, l.port);
  EXPECT_EQ(highest, 7400u + 250 * 7 + 10 + 2 * (kParticipantIdsPerDomain - 1));
  EXPECT_LT(highest + 1, 7400u + 250 * 8) << "inside domain 7's ports, clear of domain 8's";
}

TEST(StaticPeers, MoreThanThirtyTwoParticipantsFitOnOneHostByDefault) {
  EXPECT_EQ(internal::participant_ids(NetworkConfig{}, 0), 120);
  // The highest domain's last ports would not fit in 16 bits: fewer ids there.
  EXPECT_EQ(internal::participant_ids(NetworkConfig{}, 232), 63);
  EXPECT_EQ(internal::user_unicast_port(232, 62), 65535u);
}

TEST(StaticPeers, MaxParticipantsPerHostLimitsTheIdsProbed) {
  const auto net =
      NetworkConfig::from_yaml(YAML::Load("{peers: [10.77.0.1], max_participants_per_host: 8}"));
  BuiltinAttributes builtin;
  internal::configure_discovery(builtin, net, 0);
  EXPECT_EQ(builtin.initialPeersList.size(), 8u);
}

TEST(StaticPeers, OnItsOwnAddressAnnounceOnlyToTheIdsClaimedThere) {
  const int domain = oscar::test::test_domain();
  const internal::ParticipantIdClaim five(domain, "127.0.0.1", 5), nine(domain, "127.0.0.1", 9);
  ASSERT_TRUE(five && nine);
  NetworkConfig net;  // interfaces and peers: 127.0.0.1
  net.peers.push_back("10.77.0.1");
  BuiltinAttributes builtin;
  internal::configure_discovery(builtin, net, domain);
  std::vector<std::uint32_t> local;
  std::size_t remote = 0;
  for (const auto& l : builtin.initialPeersList) {
    if (address_of(l) == "127.0.0.1") {
      local.push_back(l.port);
    } else {
      ++remote;
    }
  }
  EXPECT_EQ(local, (std::vector<std::uint32_t>{internal::metatraffic_unicast_port(domain, 5),
                                               internal::metatraffic_unicast_port(domain, 9)}));
  EXPECT_EQ(remote, static_cast<std::size_t>(kParticipantIdsPerDomain)) << "another host: all";
}

TEST(DiscoveryServers, ClientsKnowEachServerByItsPrefixAndLocatorAndAnnounceToNoPeer) {
  const auto net = NetworkConfig::from_yaml(
      YAML::Load("{discovery: server, discovery_servers: [127.0.0.1, 127.0.0.1]}"));
  BuiltinAttributes builtin;
  internal::configure_discovery(builtin, net, 3);
  EXPECT_EQ(builtin.discovery_config.discoveryProtocol, DiscoveryProtocol::SUPER_CLIENT);
  EXPECT_TRUE(builtin.initialPeersList.empty()) << "no static peers";
  ASSERT_EQ(builtin.discovery_config.m_DiscoveryServers.size(), 2u);
  int index = 0;
  for (const auto& server : builtin.discovery_config.m_DiscoveryServers) {
    eprosima::fastrtps::rtps::GuidPrefix_t expected;
    eprosima::fastdds::rtps::get_server_client_default_guidPrefix(index, expected);
    EXPECT_EQ(server.guidPrefix, expected);
    ASSERT_EQ(server.metatrafficUnicastLocatorList.size(), 1u);
    const auto& l = *server.metatrafficUnicastLocatorList.begin();
    EXPECT_EQ(address_of(l), "127.0.0.1");
    EXPECT_EQ(l.port, discovery_server_port(3, index));
    EXPECT_EQ(l.port, 7400u + 250 * 3 + 10 + 2 * (119 - index));
    ++index;
  }
  EXPECT_EQ(internal::participant_ids(net, 3), 118) << "the two servers' ids are not for clients";
}

TEST(DiscoveryServers, EachServerListensOnItsOwnLocatorAndKnowsTheOther) {
  const auto net = NetworkConfig::from_yaml(
      YAML::Load("{discovery: server, discovery_servers: [127.0.0.1, 127.0.0.1]}"));
  const auto qos = internal::discovery_server_qos(net, 3, 1);
  const auto& builtin = qos.wire_protocol().builtin;
  EXPECT_EQ(builtin.discovery_config.discoveryProtocol, DiscoveryProtocol::SERVER);
  eprosima::fastrtps::rtps::GuidPrefix_t own;
  eprosima::fastdds::rtps::get_server_client_default_guidPrefix(1, own);
  EXPECT_EQ(qos.wire_protocol().prefix, own);
  ASSERT_EQ(builtin.metatrafficUnicastLocatorList.size(), 1u);
  EXPECT_EQ(builtin.metatrafficUnicastLocatorList.begin()->port, discovery_server_port(3, 1));
  EXPECT_TRUE(builtin.metatrafficMulticastLocatorList.empty()) << "no multicast";
  ASSERT_EQ(builtin.discovery_config.m_DiscoveryServers.size(), 1u);
  EXPECT_EQ(builtin.discovery_config.m_DiscoveryServers.begin()
                ->metatrafficUnicastLocatorList.begin()
                ->port,
            discovery_server_port(3, 0));
  EXPECT_THROW(internal::discovery_server_qos(net, 3, 2), std::invalid_argument);
}

TEST(DiscoveryServers, DefaultToTheFirstInterface) {
  const auto net =
      NetworkConfig::from_yaml(YAML::Load("{interfaces: [10.77.0.2], discovery: server}"));
  EXPECT_EQ(net.discovery, Discovery::kServer);
  EXPECT_EQ(net.discovery_servers, std::vector<std::string>{"10.77.0.2"});
}

TEST(DiscoveryServers, ForAHostDefaultToTheLocalHostsAddress) {
  const auto system = YAML::Load(R"(
network: { discovery: server }
hosts:
  base: { local: true, address: 10.77.0.1 }
  scooter: { netns: scooter, address: 10.77.0.2 }
)");
  const auto net = NetworkConfig::for_host(system, "scooter");
  EXPECT_EQ(net.discovery, Discovery::kServer);
  EXPECT_EQ(net.interfaces, std::vector<std::string>{"10.77.0.2"}) << "the host's own address";
  EXPECT_EQ(net.discovery_servers, std::vector<std::string>{"10.77.0.1"});
  const auto static_net = NetworkConfig::for_host(YAML::Load("{hosts: {}}"), "");
  EXPECT_EQ(static_net.discovery, Discovery::kStaticPeers);
  EXPECT_TRUE(static_net.discovery_servers.empty());
}

TEST(ParticipantIds, ASystemOfSeveralHostsProbesAsManyAsItsBusiestHostHolds) {
  const auto system = YAML::Load(R"(
hosts:
  base: { local: true, address: 10.77.0.1 }
  scooter: { netns: scooter, address: 10.77.0.2 }
modules:
  - { name: a, host: base }
  - { name: b, host: scooter }
  - { name: c, host: scooter }
  - { name: d, host: scooter }
coordinator: { host: base, applets: [ { type: t, name: x }, { type: t, name: y } ] }
)");
  // scooter's 3 modules, the coordinator and its 2 applets (counted on every host), and room.
  const int expected = 3 + 1 + 2 + kParticipantsBesideModules;
  EXPECT_EQ(NetworkConfig::for_host(system, "base").max_participants_per_host, expected);
  EXPECT_EQ(NetworkConfig::for_host(system, "scooter").max_participants_per_host, expected);
  BuiltinAttributes builtin;
  internal::configure_discovery(builtin, NetworkConfig::for_host(system, "base"), 3);
  const auto to_scooter =
      std::count_if(builtin.initialPeersList.begin(), builtin.initialPeersList.end(),
                    [](const Locator_t& l) { return IPLocator::toIPv4string(l) == "10.77.0.2"; });
  EXPECT_EQ(to_scooter, expected) << "base announces itself to that many ids of scooter";

  auto set = YAML::Clone(system);
  set["network"]["max_participants_per_host"] = 50;
  EXPECT_EQ(NetworkConfig::for_host(set, "scooter").max_participants_per_host, 50)
      << "the file's network: decides";
  const auto one_host = YAML::Load("{modules: [ { name: a } ]}");
  EXPECT_EQ(NetworkConfig::for_host(one_host, "").max_participants_per_host,
            kParticipantIdsPerDomain)
      << "on loopback a participant announces itself only to the ids claimed there";
}

TEST(DiscoveryServers, AModulesParticipantIsAPlainClientAndOnlyIt) {
  const auto net = NetworkConfig::from_yaml(YAML::Load("{discovery: server}"));
  BuiltinAttributes builtin;
  internal::configure_discovery(builtin, net, 3, DiscoveryScope::kSharedTopics);
  EXPECT_EQ(builtin.discovery_config.discoveryProtocol, DiscoveryProtocol::CLIENT);
  EXPECT_EQ(builtin.discovery_config.m_DiscoveryServers.size(), 1u);
  BuiltinAttributes whole;
  internal::configure_discovery(whole, net, 3);
  EXPECT_EQ(whole.discovery_config.discoveryProtocol, DiscoveryProtocol::SUPER_CLIENT);
}

bool sees(const DdsParticipant& p, const std::string& name) {
  const auto all = p.discovered_participants();
  return std::any_of(all.begin(), all.end(), [&](const auto& d) { return d.name == name; });
}

// A plain client is told of the participants whose endpoints share a topic with its own, and of
// no other; a super client (boot, the registry, the tools) of all.
TEST(DiscoveryServerPlainClients, LearnOnlyOfTheParticipantsTheyShareATopicWith) {
  using namespace std::chrono_literals;
  // Two free domains, the lower one used: a discovery server's port (id 119) does not fit in
  // domain 232's, the first FreeDomain tries.
  oscar::testing::FreeDomain higher, free;
  const int domain = free.domain();
  const auto net = NetworkConfig::from_yaml(YAML::Load("{discovery: server}"));
  DiscoveryServer server(domain, net, 0);
  const auto plain = [&](const std::string& name) {
    return std::make_unique<DdsParticipant>(domain, name, net, DiscoveryScope::kSharedTopics);
  };
  auto producer = plain("producer");
  auto consumer = plain("consumer");
  auto stranger = plain("stranger");
  DdsParticipant tool(domain, "tool", net);
  TopicWriter<ConfigCommand, ConfigCommandPubSubType> shared_writer(*producer, topics::config("a"));
  TopicReader<ConfigCommand, ConfigCommandPubSubType> shared_reader(
      *consumer, topics::config("a"), [](const ConfigCommand&, const auto&) {});
  TopicWriter<ConfigCommand, ConfigCommandPubSubType> other(*stranger, topics::config("b"));
  ASSERT_TRUE(eventually(
      [&] {
        return sees(tool, "producer") && sees(tool, "consumer") && sees(tool, "stranger") &&
               shared_reader.matched() > 0;
      },
      30s))
      << "the super client sees everyone, the consumer matches the producer";
  EXPECT_TRUE(sees(*consumer, "producer"));
  EXPECT_TRUE(sees(*producer, "consumer"));
  // The server has gone through what it learned many times over (every 50 ms) by now.
  std::this_thread::sleep_for(1s);
  EXPECT_FALSE(sees(*consumer, "stranger")) << "shares no topic with it";
  EXPECT_FALSE(sees(*stranger, "producer"));
  EXPECT_FALSE(sees(*stranger, "consumer"));
}

void expect_refused(const char* yaml, const char* message) {
  try {
    NetworkConfig::from_yaml(YAML::Load(yaml));
    ADD_FAILURE() << "accepted " << yaml;
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), message);
  }
}

TEST(NetworkBadInput, DiscoveryKeysAreChecked) {
  expect_refused("{discovery: mdns}", "network.discovery: 'mdns' is neither static nor server");
  expect_refused("{discovery_servers: [127.0.0.1]}",
                 "network.discovery_servers: given without discovery: server");
  expect_refused("{discovery: server, discovery_servers: [127.0.0.1, 127.0.0.1, 127.0.0.1]}",
                 "network.discovery_servers: 3 addresses; one server, or two for redundancy");
  expect_refused("{discovery: server, discovery_servers: [localhost]}",
                 "network.discovery_servers: 'localhost' is not an IPv4 address");
  expect_refused("{max_participants_per_host: 121}",
                 "network.max_participants_per_host: 121 is not in 1..120 (the ids a domain's "
                 "ports leave room for)");
}

}  // namespace
}  // namespace oscar
