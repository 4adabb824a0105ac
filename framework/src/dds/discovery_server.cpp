#include "oscar/discovery_server.hpp"

#include <stdexcept>

#include <fmt/format.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>

#include "dds/discovery.hpp"
#include "dds/participant_identity.hpp"

namespace oscar {
namespace dds = eprosima::fastdds::dds;

DiscoveryServer::DiscoveryServer(int domain, const NetworkConfig& network, int index) {
  const auto qos = internal::discovery_server_qos(network, domain, index);  // checks `index`
  const auto& address = network.discovery_servers[static_cast<std::size_t>(index)];
  locator_ = fmt::format("{}:{}", address, discovery_server_port(domain, index));
  dds_log_level_from_env();
  // Its id claimed like any participant's: no client on its address takes its ports.
  claim_ = std::make_unique<internal::ParticipantIdClaim>(domain, address,
                                                          discovery_server_participant_id(index));
  if (!*claim_) {
    throw std::runtime_error(fmt::format("discovery server {} of domain {} already runs on {}",
                                         index, domain, locator_));
  }
  participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(domain, qos);
  if (!participant_) {
    throw std::runtime_error(
        fmt::format("cannot start discovery server {} of domain {} on {} (is the port taken?)",
                    index, domain, locator_));
  }
  claim_->record(participant_->guid().guidPrefix);
}

DiscoveryServer::~DiscoveryServer() {
  if (participant_) dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

}  // namespace oscar
