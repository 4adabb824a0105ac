#include "oscar/dds_participant.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include "dds/discovery.hpp"
#include "dds/guarded_type.hpp"
#include "dds/participant_identity.hpp"
#include "dds/udp_tuning.hpp"
#include "dds/wire_bounds.hpp"
#include "oscar/raw_cdr_type.hpp"
#include "oscar/security_files.hpp"

namespace oscar {
namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;
using internal::metatraffic_unicast_port;
using internal::user_unicast_port;

namespace {

// True if nobody on this host has bound the UDP port on that address.
bool udp_port_free(const std::string& address, std::uint32_t port) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  inet_pton(AF_INET, address.c_str(), &a.sin_addr);
  const bool ok = bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  close(fd);
  return ok;
}

constexpr const char* kModulesProperty = "oscar.modules";
constexpr const char* kSystemInstanceProperty = "oscar.system_instance";

std::mutex hosted_mutex;
std::vector<std::string> hosted_modules;  // modules of system files this process hosts

std::vector<std::string> hosted() {
  std::lock_guard lock(hosted_mutex);
  return hosted_modules;
}

dds::DomainParticipantQos participant_qos(const std::string& name, const NetworkConfig& net,
                                          int domain, int participant_id, DiscoveryScope scope) {
  dds::DomainParticipantQos qos;
  qos.name(name);
  if (const auto modules = hosted(); !modules.empty()) {
    qos.properties().properties().emplace_back(
        kModulesProperty, fmt::format("{}", fmt::join(modules, ",")), true);  // propagated
  }
  if (auto instance = system_instance_from_env(); !instance.empty()) {
    qos.properties().properties().emplace_back(kSystemInstanceProperty, std::move(instance), true);
  }
  if (net.security) {
    for (auto& [property, value] :
         security_files::dds_security_properties(net.security->keystore, net.security->identity)) {
      qos.properties().properties().emplace_back(std::move(property), std::move(value));
    }
  }
  auto& transport = qos.transport();
  transport.use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList = net.interfaces;
  const auto tuning = internal::udp_tuning(net);
  if (tuning.buffer_bytes != 0) {
    // Room for a 442 KB image in one burst (udp_tuning.hpp); the kernel caps it at
    // net.core.{w,r}mem_max, which is read-only inside a network namespace.
    udp->sendBufferSize = tuning.buffer_bytes;
    udp->receiveBufferSize = tuning.buffer_bytes;
  }
  if (tuning.max_message_bytes != 0) udp->maxMessageSize = tuning.max_message_bytes;
  transport.user_transports.push_back(udp);
  if (net.shared_memory) {
    auto shm = std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>();
    shm->segment_size(shm_segment_bytes_for(net, true));
    // Fast DDS opens a port while holding the participant's lock on all sending, and waits up to
    // a third of this for the port's listener to show it is alive (1 s by default: a sender
    // stalled for up to 333 ms, heartbeats included, whenever it first sent to a quiet port;
    // `oscar bench restart` saw healthy modules declared hung). 300 ms keeps that below 100 ms.
    shm->healthy_check_timeout_ms(300);
    transport.user_transports.push_back(shm);
  }
  auto& builtin = qos.wire_protocol().builtin;
  qos.wire_protocol().participant_id = participant_id;
  // An explicit metatraffic unicast locator and no multicast locator: discovery is unicast only.
  builtin.metatrafficMulticastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.clear();
  builtin.avoid_builtin_multicast = true;
  Locator_t own;
  IPLocator::setIPv4(own, net.interfaces.front());
  own.port = metatraffic_unicast_port(domain, participant_id);
  builtin.metatrafficUnicastLocatorList.push_back(own);
  // User data: UDP on every allowed interface, and shared memory on a port of this participant's
  // own (participant_identity.hpp).
  auto& user = qos.wire_protocol().default_unicast_locator_list;
  for (const auto& address : net.interfaces) {
    Locator_t l;
    IPLocator::setIPv4(l, address);
    l.port = user_unicast_port(domain, participant_id);
    user.push_back(l);
  }
  if (net.shared_memory) user.push_back(internal::unique_shared_memory_locator());
  internal::configure_discovery(builtin, net, domain, scope);  // static peers or servers
  // Leave quickly: a vanished participant must not linger for 20 s. Announced every second, not
  // every 200 ms: each announcement goes to every participant, and booting a hundred modules on
  // two cores, UDP sends were most of their CPU time (perf; docs/network.md).
  builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(3, 0);
  builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(1, 0);
  return qos;
}

}  // namespace

int domain_from_env(int fallback) {
  const char* env = std::getenv("OSCAR_DOMAIN");
  if (!env || !*env) return fallback;
  char* end = nullptr;
  const long d = std::strtol(env, &end, 10);
  if (*end != '\0' || d < 0 || d > 232) {
    throw std::invalid_argument(fmt::format("OSCAR_DOMAIN='{}': expected 0..232", env));
  }
  return static_cast<int>(d);
}

std::string system_instance_from_env() {
  const char* env = std::getenv(kSystemInstanceEnv);
  return env ? env : "";
}

void dds_log_level_from_env() {
  using eprosima::fastdds::dds::Log;
  const char* env = std::getenv("OSCAR_DDS_LOG");
  const std::string level = env ? env : "error";
  if (level == "error") {
    Log::SetVerbosity(Log::Error);
  } else if (level == "warning") {
    Log::SetVerbosity(Log::Warning);
  } else if (level == "info") {
    Log::SetVerbosity(Log::Info);
  } else {
    throw std::invalid_argument(
        fmt::format("OSCAR_DDS_LOG='{}': expected error, warning or info", level));
  }
}

class DdsParticipant::Listener final : public dds::DomainParticipantListener {
 public:
  void on_participant_discovery(
      dds::DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERY_STATUS;
    std::lock_guard lock(mutex_);
    if (info.status == Status::DISCOVERED_PARTICIPANT) {
      auto& p = participants_[info.info.m_guid.guidPrefix];
      p.name = info.info.m_participantName.to_string();
      if (p.name.starts_with("oscar:")) p.modules.push_back(p.name.substr(6));
      for (const auto& property : info.info.m_properties) {
        if (property.first() == kSystemInstanceProperty) p.system_instance = property.second();
        if (property.first() != kModulesProperty) continue;
        std::istringstream names(property.second());
        for (std::string m; std::getline(names, m, ',');) p.modules.push_back(m);
      }
    } else if (info.status == Status::REMOVED_PARTICIPANT ||
               info.status == Status::DROPPED_PARTICIPANT) {
      participants_.erase(info.info.m_guid.guidPrefix);
    }
  }
  std::vector<DiscoveredParticipant> participants() const {
    std::lock_guard lock(mutex_);
    std::vector<DiscoveredParticipant> out;
    for (const auto& [prefix, p] : participants_) out.push_back({p.name, p.system_instance});
    return out;
  }
  std::vector<std::string> modules_in_process_of(
      const eprosima::fastrtps::rtps::GUID_t& writer) const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> modules;
    for (const auto& [prefix, p] : participants_) {
      const eprosima::fastrtps::rtps::GUID_t participant(
          prefix, eprosima::fastrtps::rtps::c_EntityId_RTPSParticipant);
      if (writer.is_on_same_process_as(participant)) {
        modules.insert(modules.end(), p.modules.begin(), p.modules.end());
      }
    }
    return modules;
  }
  void on_publisher_discovery(dds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    using Status = eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERY_STATUS;
    note(info.info.topicName().to_string(), info.info.typeName().to_string());
    const auto topic = info.info.topicName().to_string();
    const auto& guid = info.info.guid();
    if (info.status == Status::DISCOVERED_WRITER) {
      const auto& q = info.info.m_qos;
      const bool reliable = q.m_reliability.kind == dds::RELIABLE_RELIABILITY_QOS;
      const bool transient_local = q.m_durability.kind == dds::TRANSIENT_LOCAL_DURABILITY_QOS;
      std::lock_guard lock(mutex_);
      live_writers_[guid] = topic;
      writers_[topic] = {info.info.typeName().to_string(),
                         std::string(reliable ? "reliable" : "best_effort") +
                             (transient_local ? ", transient_local" : ", volatile"),
                         reliable, transient_local, count_alive(topic)};
    } else if (info.status == Status::REMOVED_WRITER) {
      std::lock_guard lock(mutex_);
      const auto live = live_writers_.find(guid);
      if (live == live_writers_.end()) return;
      const auto gone_topic = live->second;
      live_writers_.erase(live);
      if (auto it = writers_.find(gone_topic); it != writers_.end()) {
        it->second.alive = count_alive(gone_topic);
      }
    }
  }
  std::map<std::string, DdsParticipant::DiscoveredWriter> writers() const {
    std::lock_guard lock(mutex_);
    return writers_;
  }
  std::optional<DdsParticipant::DiscoveredWriter> writer(const std::string& topic) const {
    std::lock_guard lock(mutex_);
    const auto it = writers_.find(topic);
    if (it == writers_.end()) return std::nullopt;
    return it->second;
  }
  void on_subscriber_discovery(dds::DomainParticipant*,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    note(info.info.topicName().to_string(), info.info.typeName().to_string());
  }
  std::optional<std::string> type_of(const std::string& topic) const {
    std::lock_guard lock(mutex_);
    const auto it = types_.find(topic);
    if (it == types_.end()) return std::nullopt;
    return it->second;
  }

 private:
  int count_alive(const std::string& topic) const {
    int n = 0;
    for (const auto& [guid, t] : live_writers_) n += t == topic;
    return n;
  }
  void note(std::string topic, std::string type) {
    std::lock_guard lock(mutex_);
    types_[std::move(topic)] = std::move(type);
  }
  mutable std::mutex mutex_;
  std::map<std::string, std::string> types_;
  std::map<std::string, DdsParticipant::DiscoveredWriter> writers_;
  std::map<eprosima::fastrtps::rtps::GUID_t, std::string> live_writers_;  // -> topic
  struct Participant {
    std::string name;
    std::vector<std::string> modules;  // the modules its process hosts, as it says
    std::string system_instance;
  };
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, Participant> participants_;
};

DdsParticipant::DdsParticipant(int domain, const std::string& name, const NetworkConfig& network,
                               DiscoveryScope scope)
    : domain_(domain), security_(network.security), listener_(std::make_unique<Listener>()) {
  if (network.interfaces.empty()) throw std::invalid_argument("network: no interface given");
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds_log_level_from_env();
  dds::StatusMask mask = dds::StatusMask::none();
  // The lowest id no other process has claimed (see participant_identity.hpp) and whose port
  // nobody else (e.g. a plain Fast DDS program) has bound.
  const auto& address = network.interfaces.front();
  const int ids = internal::participant_ids(network, domain);
  for (int id = 0; id < ids && !participant_; ++id) {
    auto claim = std::make_unique<internal::ParticipantIdClaim>(domain, address, id);
    if (!*claim || !udp_port_free(address, metatraffic_unicast_port(domain, id))) continue;
    participant_ = factory->create_participant(
        domain, participant_qos(name, network, domain, id, scope), listener_.get(), mask);
    if (participant_) {
      claim->record(participant_->guid().guidPrefix);
      id_claim_ = std::move(claim);
    } else if (network.security) {
      // The id and its port were free: Fast DDS refused the identity's files, and would refuse
      // them for every other id too.
      throw std::runtime_error(fmt::format(
          "cannot create a DDS participant '{}' on domain {} as identity '{}' of keystore {}: "
          "Fast DDS refused its security files (a certificate of another CA or expired, "
          "permissions or governance not signed by the permissions CA, or not for domain {}); "
          "`oscar security check` says which (OSCAR_DDS_LOG=warning shows Fast DDS's reason)",
          name, domain, network.security->identity, network.security->keystore, domain));
    }
  }
  if (!participant_) {
    throw std::runtime_error(fmt::format(
        "cannot create a DDS participant '{}' on domain {}: no free participant id among {} "
        "on {} (network.max_participants_per_host; a system of several hosts makes it its "
        "busiest host's modules plus {}: set it higher in the system file's network: for more "
        "tools at once)",
        name, domain, ids, network.interfaces.front(), kParticipantsBesideModules));
  }
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
}

std::optional<std::uint32_t> DdsParticipant::shared_memory_port() const {
  for (const auto& l : participant_->get_qos().wire_protocol().default_unicast_locator_list) {
    if (l.kind == LOCATOR_KIND_SHM) return l.port;
  }
  return std::nullopt;
}

std::string DdsParticipant::permission_hint(const std::string& topic) const {
  if (!security_) return "";
  return fmt::format(
      " (identity '{}' of keystore {} may not publish on {}: `oscar security list` shows what "
      "each identity may publish)",
      security_->identity, security_->keystore, topic);
}

DdsParticipant::~DdsParticipant() {
  if (participant_) {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
}

dds::Topic& DdsParticipant::topic(const std::string& name, dds::TopicDataType* type) {
  // No type objects in discovery: Fast DDS 2.9 crashes building a dynamic type from a remote
  // type object holding a sequence of structs (TypeObjectFactory::get_sequence_identifier, seen
  // with LineSeg3DSeq). Types are matched by name; OSCAR's own registry knows them.
  type->auto_fill_type_object(false);
  type->auto_fill_type_information(false);
  // Every type is registered guarded: a sample its bytes cannot be decoded from is dropped and
  // counted, never thrown on a Fast DDS thread (guarded_type.hpp). RawCdrType keeps the bytes
  // as they come, so it needs no size check.
  const bool raw = dynamic_cast<RawCdrType*>(type) != nullptr;
  dds::TypeSupport support(
      new internal::GuardedType(type, raw ? nullptr : internal::wire_check(type->getName())));
  std::lock_guard lock(mutex_);
  if (auto it = topics_.find(name); it != topics_.end()) {
    if (it->second->get_type_name() != support.get_type_name()) {
      throw std::invalid_argument(fmt::format("topic '{}' carries {}, not {}", name,
                                              it->second->get_type_name(),
                                              support.get_type_name()));
    }
    return *it->second;
  }
  if (auto seen = listener_->type_of(name); seen && *seen != support.get_type_name()) {
    throw std::invalid_argument(fmt::format("topic '{}' carries {} in the running system, not {}",
                                            name, *seen, support.get_type_name()));
  }
  if (!participant_->find_type(support.get_type_name())) support.register_type(participant_);
  auto* topic = participant_->create_topic(name, support.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  if (!topic) throw std::runtime_error(fmt::format("cannot create topic '{}'", name));
  topics_[name] = topic;
  return *topic;
}

std::optional<std::string> DdsParticipant::discovered_type(const std::string& topic) const {
  return listener_->type_of(topic);
}

std::map<std::string, DdsParticipant::DiscoveredWriter> DdsParticipant::discovered_writers() const {
  return listener_->writers();
}

std::vector<std::string> DdsParticipant::modules_in_process_of(
    const eprosima::fastrtps::rtps::GUID_t& writer) const {
  auto modules = listener_->modules_in_process_of(writer);
  if (writer.is_on_same_process_as(participant_->guid())) {
    const auto here = hosted();
    modules.insert(modules.end(), here.begin(), here.end());
  }
  return modules;
}

void internal::note_hosted_module(const std::string& module) {
  std::lock_guard lock(hosted_mutex);
  if (std::find(hosted_modules.begin(), hosted_modules.end(), module) == hosted_modules.end()) {
    hosted_modules.push_back(module);
  }
}

std::vector<DdsParticipant::DiscoveredParticipant> DdsParticipant::discovered_participants() const {
  return listener_->participants();
}

std::optional<DdsParticipant::DiscoveredWriter> DdsParticipant::discovered_writer(
    const std::string& topic) const {
  return listener_->writer(topic);
}

}  // namespace oscar
