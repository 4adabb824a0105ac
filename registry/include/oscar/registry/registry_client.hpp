#pragma once
/// @file RegistryClient: what boot and the `oscar` tools use to follow the system state and to
/// ask the registry for a restart or a shutdown.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <oscar/registry.h>

#include "oscar/dds_participant.hpp"
#include "oscar/registry/running_systems.hpp"

namespace oscar {

class RegistryClient {
 public:
  /// `on_state` (optional) is called for every system state, on a DDS thread.
  RegistryClient(DdsParticipant& participant, std::string sender,
                 std::function<void(const SystemState&)> on_state = {});
  ~RegistryClient();

  /// The newest state that satisfies `pred`, once one arrives within `timeout`.
  std::optional<SystemState> wait_for(const std::function<bool(const SystemState&)>& pred,
                                      std::chrono::milliseconds timeout);
  /// The system state as a tool reads it once: waits up to `wait`; a registry found by then (its
  /// state writer discovered) gets as long again to send it, since on a loaded host discovery
  /// takes a while. None if nothing came (registry_found() tells why).
  std::optional<SystemState> current_state(std::chrono::milliseconds wait);
  /// Whether a registry's state writer has been discovered.
  bool registry_found() const;
  /// The newest state seen so far.
  std::optional<SystemState> latest();
  /// Sends a request and waits for the registry's answer.
  /// @throws std::runtime_error if no registry answers within `timeout`, or with its refusal.
  void request(RegistryRequestKind kind, const std::string& module,
               std::chrono::milliseconds timeout = std::chrono::milliseconds(5000));

 private:
  struct Endpoints;
  std::string sender_;
  std::function<void(const SystemState&)> on_state_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<SystemState> latest_;
  std::map<unsigned long long, RegistryReply> replies_;
  unsigned long long id_base_;     ///< this process's: its pid in the high bits
  std::unique_ptr<Endpoints> io_;  // last: its callbacks use the members above
};

/// The system a tool looks at when told nothing: the one `oscar boot` runs on this machine.
/// @throws std::invalid_argument if several run (listing them: the user must choose).
std::optional<RunningSystem> default_system();

/// What to add when a tool found no system on `domain`: the systems booted on this machine and
/// how to name one, or that none was, e.g. " (running on this machine: ...; name one with -d)".
std::string where_systems_run(int domain);

/// Why `client.current_state(wait)` gave no state, for a tool's error line: a registry it found
/// sent none (is it hung?), or no registry answered on `domain` at all (with where_systems_run()).
std::string why_no_state(const RegistryClient& client, int domain, std::chrono::milliseconds wait);

/// What a command-line tool may do in a secured system (docs/security.md): look (the
/// `operator` identity, which may write nothing) or act with boot's authority
/// (`operator_boot`: configure modules, ask the registry to restart or shut down).
enum class ToolAuthority { kLook, kActAsBoot };

/// The participant of a command-line tool: with `system_file`, that system's domain and the
/// network of its host `host` (default: its local host); `domain` >= 0 overrides the domain.
/// Without a file it takes the domain given, else $OSCAR_DOMAIN, else that of the system booted
/// on this machine (see default_system()), else domain 0; and the file of the system booted on
/// that domain here, if any (its network: addresses, discovery servers), else loopback. It
/// authenticates with the system's keystore ($OSCAR_KEYSTORE, the file's, or the one boot was
/// given) as the identity `authority` names, if the system has one.
/// @throws std::invalid_argument if several systems run and none was named.
std::unique_ptr<DdsParticipant> tool_participant(const std::string& name, std::string system_file,
                                                 const std::string& host, int domain,
                                                 ToolAuthority authority = ToolAuthority::kLook);

}  // namespace oscar
