#pragma once
/// @file One DDS participant per process, created with OSCAR's network profile, with cached
/// topics and a map of the topic types discovery has seen (for clear type-mismatch errors).

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "oscar/network.hpp"

namespace oscar {
namespace internal {
class ParticipantIdClaim;
}

namespace internal {
/// Marks this process as hosting `module` (a module of a system file): every participant it
/// creates from then on carries the names in discovery (property "oscar.modules"), whatever
/// its own name. Called by Module before it constructs its kernels.
void note_hosted_module(const std::string& module);
}  // namespace internal

class DdsParticipant {
 public:
  /// `scope`: what it learns of where `network` uses discovery servers (a module's
  /// participant: only what shares a topic with it).
  /// @throws std::runtime_error if no participant can be created (e.g. all ports taken).
  DdsParticipant(int domain, const std::string& name, const NetworkConfig& network = {},
                 DiscoveryScope scope = DiscoveryScope::kWholeSystem);
  ~DdsParticipant();
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;

  eprosima::fastdds::dds::DomainParticipant& get() { return *participant_; }
  eprosima::fastdds::dds::Publisher& publisher() { return *publisher_; }
  eprosima::fastdds::dds::Subscriber& subscriber() { return *subscriber_; }
  int domain() const { return domain_; }
  /// The shared-memory port this participant listens on (/dev/shm/fastrtps_port<N>); none
  /// without the shared-memory transport.
  std::optional<std::uint32_t> shared_memory_port() const;
  /// What a writer that could not be made on `topic` may be missing: under DDS Security, the
  /// permission of this participant's identity (" (identity 'module.a' of keystore K may not
  /// publish on it ...)"); "" for a plain participant.
  std::string permission_hint(const std::string& topic) const;

  /// The topic of that name, registering the type if needed.
  /// @throws std::invalid_argument if the topic exists here with another type, or if discovery
  ///         saw the topic with another type elsewhere (naming both types).
  eprosima::fastdds::dds::Topic& topic(const std::string& name,
                                       eprosima::fastdds::dds::TopicDataType* type);
  /// The type discovery has seen for a topic (from remote writers and readers), if any.
  std::optional<std::string> discovered_type(const std::string& topic) const;
  /// A remote writer discovery has seen: its topic's type and its QoS, e.g. "reliable, volatile".
  struct DiscoveredWriter {
    std::string type;
    std::string qos;
    bool reliable = true;
    bool transient_local = false;
    /// How many remote writers of the topic discovery sees now; 0 once all have gone (the
    /// entry stays, so a topic's last type and QoS are still known).
    int alive = 0;
  };
  /// Every topic with a remote writer, by name (what `oscar record` subscribes to).
  std::map<std::string, DiscoveredWriter> discovered_writers() const;
  /// Another participant on the domain, as discovery sees it.
  struct DiscoveredParticipant {
    std::string name;  ///< a module's is "oscar:<module>"
    /// The booted system its process belongs to ($OSCAR_SYSTEM_INSTANCE there); "" if none.
    std::string system_instance;
  };
  /// The other participants on the domain that discovery sees now.
  std::vector<DiscoveredParticipant> discovered_participants() const;
  /// The modules hosted by the process of `writer`, as discovery shows them: all participants
  /// of one process share the first 8 bytes of their GUID prefix (host and process); a module's
  /// participant is named "oscar:<module>", and every participant made in a process that hosts a
  /// module of a system file says so (internal::note_hosted_module). Where a sample really comes
  /// from, whatever it says.
  std::vector<std::string> modules_in_process_of(
      const eprosima::fastrtps::rtps::GUID_t& writer) const;
  /// The last remote writer discovery has seen on `topic`, if any.
  std::optional<DiscoveredWriter> discovered_writer(const std::string& topic) const;

 private:
  class Listener;
  int domain_;
  std::string name_;
  std::optional<ParticipantSecurity> security_;
  std::unique_ptr<Listener> listener_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  std::unique_ptr<internal::ParticipantIdClaim> id_claim_;  ///< released after the participant
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::mutex mutex_;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
};

}  // namespace oscar
