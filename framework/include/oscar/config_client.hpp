#pragma once
/// @file ConfigClient: sends configuration commands to modules and waits for their replies
/// (what boot, the registry, the coordinator and `oscar config` use).

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <oscar/config.h>

#include "oscar/dds_participant.hpp"
#include "oscar/idl_type_info.hpp"

namespace oscar {

class ConfigClient {
 public:
  /// `sender` is the authority the commands carry: "coordinator", "registry", "boot" or a name.
  ConfigClient(DdsParticipant& participant, std::string sender);
  ~ConfigClient();

  /// Opens the channel to `module` now: its endpoints find the module's in the background, so
  /// the first command does not wait for discovery (a caller with a short timeout, such as the
  /// coordinator's proposals to robots, opens its channels when it starts).
  void connect(const std::string& module);

  /// Sends a command and waits for the module's reply.
  /// @throws std::runtime_error "no module named 'x' is running" if no module reads
  ///         oscar/config/<module> within `timeout`, or if the reply does not come in time.
  ConfigReply send(const std::string& module, CommandKind kind, std::vector<std::string> args,
                   std::chrono::milliseconds timeout = std::chrono::milliseconds(3000));

  /// Sends `request` to the command port `command` of `kernel` in `module` (docs/kernels.md,
  /// "Command ports") and waits for the answer: ok() is true when the kernel accepted it,
  /// answered() when the kernel's handler ran (ok() is then its verdict), answer() is the
  /// kernel's text and error() says why the command was refused.
  /// @throws std::runtime_error as send() does.
  template <IdlStruct T>
  ConfigReply command(const std::string& module, const std::string& kernel,
                      const std::string& command, const T& request,
                      std::chrono::milliseconds timeout = std::chrono::milliseconds(3000)) {
    const auto& type = idl_type_info<T>();
    return send_command(module, kernel, command, type.name, type.serialize(&request), timeout);
  }
  /// The same with the request as CDR bytes of the IDL type `type` (what `oscar config ...
  /// command` sends after encoding its YAML).
  ConfigReply send_command(const std::string& module, const std::string& kernel,
                           const std::string& command, const std::string& type,
                           std::vector<std::uint8_t> cdr,
                           std::chrono::milliseconds timeout = std::chrono::milliseconds(3000));

  /// The state `module` published last (on oscar/registry/module_state; a module publishes it
  /// every second and at each transition): its kernels and their command ports.
  /// @throws std::runtime_error if none arrives within `timeout`.
  ModuleState module_state(const std::string& module,
                           std::chrono::milliseconds timeout = std::chrono::milliseconds(3000));

 private:
  ConfigReply send(ConfigCommand command, std::chrono::milliseconds timeout);
  struct Channel;
  Channel& channel(const std::string& module);

  DdsParticipant& participant_;
  std::string sender_;
  std::mutex mutex_;
  std::map<std::string, std::unique_ptr<Channel>> channels_;
  unsigned long long next_id_ = 1;
};

/// "activate" -> CMD_ACTIVATE etc. @throws std::invalid_argument listing the kinds.
CommandKind parse_command_kind(const std::string& text);

}  // namespace oscar
