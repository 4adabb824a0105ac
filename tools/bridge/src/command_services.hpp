#pragma once
// Kernel command ports as Foxglove services (docs/foxglove.md, "Kernel commands from
// Foxglove"): with --allow-config, every command a running module's kernel declares is the
// service oscar/<module>/<kernel>/<command>. Its request schema is a JSON schema made from the
// request's IDL type (members, their types, enumerators); a call's JSON is encoded to that type's
// CDR as `oscar config ... command` encodes YAML, so nothing a client sends is run. The
// services follow the registry's system state: a module that starts running is advertised, one
// that stops is unadvertised, and a service keeps its id when its module comes back.

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <oscar/registry.h>

#include "foxglove_protocol.hpp"
#include "idl_types.hpp"  // tools/inspect

namespace oscar::bridge {

/// One command port of a kernel of a running module.
struct KernelCommand {
  std::string module;
  std::string kernel;
  std::string name;          ///< e.g. "frame_mode"
  std::string request_type;  ///< its request's IDL type, e.g. "oscar::SetFrameMode"
  /// "oscar/<module>/<kernel>/<command>", the service's name.
  std::string service_name() const;
  bool operator==(const KernelCommand&) const = default;
};

/// The command ports of the kernels of every module `state` lists as running, in the order the
/// registry lists modules and each module its kernels.
std::vector<KernelCommand> running_commands(const SystemState& state);

/// The JSON schema of a request of the IDL struct `type`: an object with each member (numbers,
/// booleans, strings, arrays, nested objects; an enum as its enumerators' names; 64-bit integers
/// also as strings of digits, which JavaScript keeps exact).
/// @throws std::invalid_argument if `types` has no struct `type`.
std::string request_json_schema(const inspect::IdlTypes& types, const std::string& type);

/// The CDR encoding (with its encapsulation header) of the request `payload`, a JSON object, as
/// the IDL struct `type`: a member left out takes its IDL default, as in `oscar config ...
/// command`.
/// @throws std::invalid_argument naming the member and the rule (no JSON object, an unknown
///         member, a value of the wrong type or out of range, an unknown enumerator).
std::vector<std::uint8_t> request_cdr(const inspect::IdlTypes& types, const std::string& type,
                                      std::string_view payload);

/// The response to a command the kernel accepted (schema oscar.CommandResponse).
std::string command_response_json(const KernelCommand& command, const std::string& answer);

/// The command services advertised now, with ids that stay with a service (module, kernel,
/// command and request type) across its module's restarts.
class CommandServices {
 public:
  /// Ids are given from `first_id` on.
  CommandServices(const inspect::IdlTypes& types, std::uint32_t first_id);

  struct Change {
    std::vector<ServiceInfo> added;
    std::vector<std::uint32_t> removed;
    /// Commands not offered because their request type has no IDL text here (said once each).
    std::vector<KernelCommand> unknown_types;
  };
  /// Makes `commands` the services offered.
  Change update(const std::vector<KernelCommand>& commands);

  std::vector<ServiceInfo> services() const;
  /// The command behind the service `id` if it is offered now.
  const KernelCommand* offered(std::uint32_t id) const;
  /// The command behind the service `id` if it was ever offered (to name what went).
  const KernelCommand* ever(std::uint32_t id) const;

 private:
  ServiceInfo info(std::uint32_t id, const KernelCommand& command) const;

  const inspect::IdlTypes& types_;
  std::uint32_t next_id_;
  std::map<std::uint32_t, KernelCommand> known_;  // every id ever given
  std::map<std::uint32_t, ServiceInfo> offered_;  // advertised now
  std::map<std::string, std::uint32_t> id_of_;    // service name + request type -> id
  std::map<std::string, bool> reported_unknown_;  // request types said to be unknown
};

}  // namespace oscar::bridge
