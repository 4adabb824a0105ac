#pragma once
// The Foxglove service "oscar/config" (docs/foxglove.md, "Configuring modules from Foxglove"):
// a configuration command to a module, in the words of `oscar config`, sent with the
// coordinator's authority. Offered only when the bridge is started with --allow-config; the
// commands go out on a thread of their own, so the bridge never waits for a module's reply.
// Only the listed command kinds are offered, each with its arguments as strings: nothing a
// client sends becomes a program, a file or a shell command.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <oscar/config.h>

#include "command_services.hpp"
#include "foxglove_protocol.hpp"
#include "oscar/dds_participant.hpp"

namespace oscar::bridge {

/// One configuration command as a service call asks for it: oscar/config's kinds, or
/// CMD_COMMAND for a kernel's command port (a command service).
struct ConfigRequest {
  std::string module;
  CommandKind kind = CMD_ACTIVATE;
  std::vector<std::string> args;
  KernelCommand command{};                  ///< CMD_COMMAND: the command port called
  std::vector<std::uint8_t> request_cdr{};  ///< CMD_COMMAND: its request, CDR encoded
  /// "sources set-cycle sig 10ms" or "robot command r7 commit": the command in `oscar config`'s
  /// words, for logs and errors.
  std::string text() const;
};

/// The service as advertised, with id `id`.
ServiceInfo config_service_info(std::uint32_t id);

/// Reads a call's JSON payload, e.g. {"module":"sources","command":"set-cycle",
/// "args":["sig","10ms"]}.
/// @throws std::invalid_argument naming what is wrong: no JSON object, "module" missing or
///         empty, a command that is not offered (shutdown and kernel commands are not), "args"
///         not an array of strings.
ConfigRequest parse_config_request(std::string_view payload);

/// The response to an accepted command (schema oscar.ConfigResponse): the module's state after
/// it.
std::string config_response_json(const ConfigReply& reply);

/// Sends configuration commands one after the other on a thread of its own.
class ConfigWorker {
 public:
  struct Outcome {
    bool ok = false;
    std::string text;  ///< ok: the response (JSON); else why the command failed
  };
  using Done = std::function<void(Outcome)>;

  /// Commands are sent as `sender` (the authority the modules check) from `participant`.
  ConfigWorker(DdsParticipant& participant, std::string sender, std::size_t max_pending = 8);
  /// Finishes the command being sent (its `done` still runs) and drops those waiting.
  ~ConfigWorker();
  ConfigWorker(const ConfigWorker&) = delete;
  ConfigWorker& operator=(const ConfigWorker&) = delete;

  /// Queues `request`; `done` runs on the worker's thread once the module replied or the wait
  /// ended. False (and `done` never runs) if `max_pending` commands are waiting already.
  bool submit(ConfigRequest request, Done done);

 private:
  void run();

  DdsParticipant& participant_;
  std::string sender_;
  std::size_t max_pending_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::pair<ConfigRequest, Done>> pending_;
  bool stop_ = false;
  std::thread thread_;  // last: it uses the members above
};

}  // namespace oscar::bridge
