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

/// True if a process of this host's RouDi offers `topic` with cues of `type_name` (an iceoryx
/// publisher of its service). Needs join_roudi() first.
bool offered_on_this_host(const std::string& topic, const std::string& type_name);

/// The iceoryx topic of the DDS topic `topic` in DDS domain `domain`: systems of other domains
/// on the same host never meet.
std::string zero_copy_topic(int domain, const std::string& topic);

}  // namespace oscar::zero_copy
