#pragma once
/// @file This process and the host's RouDi, iceoryx's shared-memory daemon (docs/zero_copy.md).

#include <optional>
#include <string>

namespace oscar::zero_copy {

/// True if a RouDi listens on this host (its socket /tmp/roudi takes a connection). Never blocks.
bool roudi_running();

/// Registers this process with the host's RouDi as `name` (once per process: after a success,
/// later calls return at once, whatever name they give). iceoryx itself would wait a minute for an
/// absent RouDi and then abort, so this asks first.
/// @throws std::invalid_argument for a name iceoryx cannot take (empty, too long, with '/').
/// @return nothing when registered, else why not (no RouDi, iox-roudi not installed).
std::optional<std::string> join_roudi(const std::string& name);

}  // namespace oscar::zero_copy
