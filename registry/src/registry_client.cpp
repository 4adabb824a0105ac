#include "oscar/registry/registry_client.hpp"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <oscar/registryPubSubTypes.h>

#include "oscar/registry/system_spec.hpp"
#include "oscar/security_files.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar {

struct RegistryClient::Endpoints {
  TopicReader<SystemState, SystemStatePubSubType> states;
  TopicReader<RegistryReply, RegistryReplyPubSubType> replies;
  // Made at the first request: a client that only watches writes nothing, which is all a
  // read-only identity may do in a secured system.
  DdsParticipant& participant;
  std::mutex requests_mutex{};
  std::optional<TopicWriter<RegistryRequest, RegistryRequestPubSubType>> requests{};

  TopicWriter<RegistryRequest, RegistryRequestPubSubType>& request_writer() {
    std::lock_guard lock(requests_mutex);
    if (!requests) requests.emplace(participant, topics::registry_request());
    return *requests;
  }
};

RegistryClient::RegistryClient(DdsParticipant& participant, std::string sender,
                               std::function<void(const SystemState&)> on_state)
    : sender_(std::move(sender)),
      on_state_(std::move(on_state)),
      id_base_(static_cast<unsigned long long>(getpid()) << 24) {
  io_.reset(new Endpoints{{participant, topics::system_state(),
                           [this](const SystemState& s, const auto&) {
                             if (on_state_) on_state_(s);
                             std::lock_guard lock(mutex_);
                             latest_ = s;
                             changed_.notify_all();
                           }},
                          {participant, topics::registry_reply(),
                           [this](const RegistryReply& r, const auto&) {
                             std::lock_guard lock(mutex_);
                             replies_[r.id()] = r;
                             changed_.notify_all();
                           }},
                          participant});
}

RegistryClient::~RegistryClient() { io_.reset(); }

std::optional<SystemState> RegistryClient::wait_for(
    const std::function<bool(const SystemState&)>& pred, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  if (changed_.wait_for(lock, timeout, [&] { return latest_ && pred(*latest_); })) return latest_;
  return std::nullopt;
}

std::optional<SystemState> RegistryClient::current_state(std::chrono::milliseconds wait) {
  const auto any = [](const SystemState&) { return true; };
  auto s = wait_for(any, wait);
  if (!s && registry_found()) s = wait_for(any, wait);
  return s;
}

bool RegistryClient::registry_found() const { return io_->states.matched() > 0; }

std::optional<SystemState> RegistryClient::latest() {
  std::lock_guard lock(mutex_);
  return latest_;
}

void RegistryClient::request(RegistryRequestKind kind, const std::string& module,
                             std::chrono::milliseconds timeout) {
  RegistryRequest q;
  // Unique in this process, not only in this client: the registry's replies reach every
  // client, and one made after another would otherwise take the other's reply for its own.
  static std::atomic<unsigned long long> requests_in_process{0};
  const unsigned long long id = id_base_ + ++requests_in_process;
  q.id(id);
  q.sender(sender_);
  q.kind(kind);
  q.module_name(module);
  // Wait for the registry's reader first: a request nobody matched would be lost in silence.
  const auto until = std::chrono::steady_clock::now() + timeout;
  auto& requests = io_->request_writer();
  while (requests.matched() == 0) {
    if (std::chrono::steady_clock::now() > until) {
      throw std::runtime_error("no registry is running on this domain (is the system booted?)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  requests.write(q);
  std::unique_lock lock(mutex_);
  if (!changed_.wait_until(lock, until, [&] { return replies_.contains(id); })) {
    throw std::runtime_error("the registry did not answer in time");
  }
  const auto reply = replies_[id];
  if (!reply.ok()) throw std::runtime_error(reply.error());
}

std::optional<RunningSystem> default_system() {
  const auto systems = running_systems();
  if (systems.size() <= 1) return systems.empty() ? std::nullopt : std::optional(systems.front());
  std::string list;
  for (const auto& s : systems) list += "\n  " + s.describe();
  throw std::invalid_argument(fmt::format(
      "{} systems are running on this machine; name one with -d DOMAIN:{}", systems.size(), list));
}

std::string where_systems_run(int domain) {
  std::vector<std::string> others;
  for (const auto& s : running_systems()) {
    if (s.domain != domain) others.push_back(s.describe());
  }
  if (!others.empty()) {
    return fmt::format(" (running on this machine: {}; name one with -d DOMAIN)",
                       fmt::join(others, "; "));
  }
  return " (no system was booted on this machine with `oscar boot`; name the domain of one with "
         "-d DOMAIN, $OSCAR_DOMAIN or --system FILE)";
}

std::string why_no_state(const RegistryClient& client, int domain, std::chrono::milliseconds wait) {
  const double seconds = std::chrono::duration<double>(wait).count();
  if (client.registry_found()) {
    // current_state() gave a registry it found as long again.
    return fmt::format(
        "the registry on domain {} sent no state within {:.1f} s (is it hung? its log is "
        "registry.log in the system's log folder)",
        domain, 2 * seconds);
  }
  return fmt::format("no registry answered on domain {} within {:.1f} s{}", domain, seconds,
                     where_systems_run(domain));
}

std::unique_ptr<DdsParticipant> tool_participant(const std::string& name, std::string system_file,
                                                 const std::string& host, int domain,
                                                 ToolAuthority authority) {
  const std::string identity = authority == ToolAuthority::kActAsBoot
                                   ? security_files::kOperatorBoot
                                   : security_files::kOperator;
  if (system_file.empty()) {
    // The system booted on this machine (on the domain named, if one was), with its own network
    // profile: its hosts' addresses, or its discovery servers.
    if (domain < 0) domain = domain_from_env(-1);
    const auto running = domain < 0 ? default_system() : running_system(domain);
    if (domain < 0) domain = running ? running->domain : 0;
    if (running && std::filesystem::exists(running->file)) system_file = running->file;
  }
  NetworkConfig network;
  std::optional<SystemSpec> system;
  if (!system_file.empty()) {
    system = SystemSpec::load(system_file);
    if (domain < 0) domain = system->domain;
    network = system->network_for((host.empty() ? system->local_host() : system->host(host)).name,
                                  identity);
  }
  if (!network.security) {
    // $OSCAR_KEYSTORE, else the keystore `oscar boot --keystore` was given for this domain.
    std::string keystore = system ? "" : security_files::keystore_from_env();
    if (const auto running = running_system(domain); keystore.empty() && running) {
      keystore = running->keystore;
    }
    if (!keystore.empty()) network.security = ParticipantSecurity{keystore, identity};
  }
  return std::make_unique<DdsParticipant>(domain, name, network);
}

}  // namespace oscar
