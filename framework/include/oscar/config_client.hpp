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

namespace oscar {

class ConfigClient {
 public:
  /// `sender` is the authority the commands carry: "coordinator", "registry", "boot" or a name.
  ConfigClient(DdsParticipant& participant, std::string sender);
  ~ConfigClient();

  /// Sends a command and waits for the module's reply.
  /// @throws std::runtime_error "no module named 'x' is running" if no module reads
  ///         oscar/config/<module> within `timeout`, or if the reply does not come in time.
  ConfigReply send(const std::string& module, CommandKind kind, std::vector<std::string> args,
                   std::chrono::milliseconds timeout = std::chrono::milliseconds(3000));

 private:
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
