#pragma once
/// @file A Fast DDS discovery server for the participants of a system (docs/network.md).

#include <memory>
#include <string>

#include "oscar/network.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipant;
}

namespace oscar {
namespace internal {
class ParticipantIdClaim;
}

/// Discovery server `index` of a system's network (`discovery: server`): a participant that
/// every other participant of the domain is a client of. `oscar boot` runs each in a process of
/// its own (`oscar-discovery-server`); with two, either one keeps the system discovering.
class DiscoveryServer {
 public:
  /// Listens on `network.discovery_servers[index]`, port discovery_server_port(domain, index).
  /// @throws std::invalid_argument if the network names no server `index`.
  /// @throws std::runtime_error if that server already runs (its id or port is taken).
  DiscoveryServer(int domain, const NetworkConfig& network, int index);
  ~DiscoveryServer();
  DiscoveryServer(const DiscoveryServer&) = delete;
  DiscoveryServer& operator=(const DiscoveryServer&) = delete;

  /// "127.0.0.1:7648": where clients reach it.
  const std::string& locator() const { return locator_; }

 private:
  std::unique_ptr<internal::ParticipantIdClaim> claim_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  std::string locator_;
};

}  // namespace oscar
