// A system's or module's `network:` map, and what a host of a system file gets (docs/network.md).
#include <arpa/inet.h>

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dds/udp_tuning.hpp"
#include "oscar/network.hpp"

namespace oscar {
namespace {

bool is_ipv4(const std::string& s) {
  in_addr a{};
  return inet_pton(AF_INET, s.c_str(), &a) == 1;
}

// The participants the system file puts on one of its hosts at most, and room for the others:
// each host's modules, plus the coordinator and each of its applets (an applet may run in a
// process of its own), counted on every host. Unmapped or odd input counts as nothing: the
// system file's own checks report it.
int participants_per_host(const YAML::Node& system) {
  // A key the file does not have is an invalid node, whose type yaml-cpp refuses to tell.
  const auto is = [](const YAML::Node& n, YAML::NodeType::value type) {
    return n && n.Type() == type;
  };
  std::map<std::string, int> modules;  // host -> its modules
  const auto hosts = system["hosts"];
  const std::string only_host = is(hosts, YAML::NodeType::Map) && hosts.size() == 1
                                    ? hosts.begin()->first.as<std::string>()
                                    : "";
  if (const auto list = system["modules"]; is(list, YAML::NodeType::Sequence)) {
    for (const auto& m : list) {
      if (!m.IsMap()) continue;
      const auto host = m["host"];
      ++modules[is(host, YAML::NodeType::Scalar) ? host.as<std::string>() : only_host];
    }
  }
  int most = 0;
  for (const auto& [name, count] : modules) most = std::max(most, count);
  if (const auto coordinator = system["coordinator"]; is(coordinator, YAML::NodeType::Map)) {
    const auto applets = coordinator["applets"];
    most += 1 + (is(applets, YAML::NodeType::Sequence) ? static_cast<int>(applets.size()) : 0);
  }
  return std::min(most + kParticipantsBesideModules, kParticipantIdsPerDomain);
}

}  // namespace

NetworkConfig NetworkConfig::from_yaml(const YAML::Node& node, NetworkConfig base) {
  NetworkConfig net = std::move(base);
  if (!node || node.IsNull()) return net;
  if (!node.IsMap()) throw std::invalid_argument("network: expected a map");
  const auto addresses = [](const YAML::Node& list, const char* key) {
    std::vector<std::string> out;
    if (!list.IsSequence() || list.size() == 0) {
      throw std::invalid_argument(fmt::format("network.{}: expected a non-empty list", key));
    }
    for (const auto& a : list) {
      const auto s = a.as<std::string>();
      if (!is_ipv4(s)) {
        throw std::invalid_argument(fmt::format("network.{}: '{}' is not an IPv4 address", key, s));
      }
      out.push_back(s);
    }
    return out;
  };
  bool servers_given = false;
  for (const auto& kv : node) {
    const auto key = kv.first.as<std::string>();
    if (key == "interfaces") {
      net.interfaces = addresses(kv.second, "interfaces");
    } else if (key == "peers") {
      net.peers = addresses(kv.second, "peers");
    } else if (key == "shared_memory") {
      net.shared_memory = kv.second.as<bool>();
    } else if (key == "shm_segment_bytes") {
      const auto bytes = kv.second.as<std::uint32_t>();
      // Fast DDS sends messages of up to 65500 bytes through shared memory, and refuses the
      // transport (silently, for us) with a segment smaller than one message.
      if (bytes < 65536)
        throw std::invalid_argument(
            fmt::format("network.shm_segment_bytes: {} is smaller than 65536 (Fast DDS's "
                        "largest message through shared memory must fit)",
                        bytes));
      net.shm_segment_bytes = bytes;
    } else if (key == "udp_buffer_bytes") {
      net.udp_buffer_bytes =
          internal::udp_buffer_bytes("network.udp_buffer_bytes", kv.second.as<std::string>());
    } else if (key == "udp_max_message_bytes") {
      net.udp_max_message_bytes = internal::udp_max_message_bytes("network.udp_max_message_bytes",
                                                                  kv.second.as<std::string>());
    } else if (key == "max_participants_per_host") {
      net.max_participants_per_host = kv.second.as<int>();
      if (net.max_participants_per_host < 1 ||
          net.max_participants_per_host > kParticipantIdsPerDomain) {
        throw std::invalid_argument(
            fmt::format("network.max_participants_per_host: {} is not in 1..{} (the ids a domain's "
                        "ports leave room for)",
                        net.max_participants_per_host, kParticipantIdsPerDomain));
      }
    } else if (key == "discovery") {
      const auto kind = kv.second.as<std::string>();
      if (kind == "static") {
        net.discovery = Discovery::kStaticPeers;
      } else if (kind == "server") {
        net.discovery = Discovery::kServer;
      } else {
        throw std::invalid_argument(
            fmt::format("network.discovery: '{}' is neither static nor server", kind));
      }
    } else if (key == "discovery_servers") {
      net.discovery_servers = addresses(kv.second, "discovery_servers");
      servers_given = true;
      if (net.discovery_servers.size() > 2) {
        throw std::invalid_argument(fmt::format(
            "network.discovery_servers: {} addresses; one server, or two for redundancy",
            net.discovery_servers.size()));
      }
    } else {
      throw std::invalid_argument(
          fmt::format("network: unknown key '{}' (allowed: interfaces, peers, shared_memory, "
                      "shm_segment_bytes, udp_buffer_bytes, udp_max_message_bytes, "
                      "max_participants_per_host, discovery, discovery_servers)",
                      key));
    }
  }
  if (servers_given && net.discovery != Discovery::kServer) {
    throw std::invalid_argument("network.discovery_servers: given without discovery: server");
  }
  if (net.discovery == Discovery::kServer && net.discovery_servers.empty()) {
    net.discovery_servers = {net.interfaces.front()};
  }
  return net;
}

NetworkConfig NetworkConfig::from_yaml(const YAML::Node& node) {
  return from_yaml(node, NetworkConfig{});
}

NetworkConfig NetworkConfig::for_host(const YAML::Node& system, const std::string& host) {
  NetworkConfig net;
  const auto hosts = system["hosts"];
  if (hosts && hosts.IsMap()) {
    if (!host.empty() && hosts[host] && hosts[host]["address"]) {
      net.interfaces = {hosts[host]["address"].as<std::string>()};
      net.peers.clear();
      for (const auto& kv : hosts) {
        if (kv.second.IsMap() && kv.second["address"]) {
          net.peers.push_back(kv.second["address"].as<std::string>());
        }
      }
      // A participant announces itself to every participant id of every other host: only
      // as many as the file can put there (docs/network.md, "Participant ids per host").
      net.max_participants_per_host = participants_per_host(system);
    }
    // Boot starts the discovery servers on its own host: every host's processes reach them there.
    for (const auto& kv : hosts) {
      if (kv.second.IsMap() && kv.second["local"] && kv.second["address"]) {
        net.discovery_servers = {kv.second["address"].as<std::string>()};
        break;
      }
    }
  }
  if (net.discovery_servers.empty()) net.discovery_servers = {"127.0.0.1"};
  // from_yaml keeps these only for discovery: server (where they are the default).
  const auto default_servers = std::move(net.discovery_servers);
  net.discovery_servers.clear();
  net = from_yaml(system["network"], std::move(net));
  if (net.discovery == Discovery::kServer && !system["network"]["discovery_servers"]) {
    net.discovery_servers = default_servers;
  }
  return net;
}

std::uint32_t shm_segment_bytes_for(const NetworkConfig& network, bool publishes_cues) {
  return network.shm_segment_bytes.value_or(publishes_cues ? kCueShmSegmentBytes
                                                           : kQuietShmSegmentBytes);
}

}  // namespace oscar
