#pragma once
// Which modules a module's boot start waits for (internal to the registry).

#include <cstddef>
#include <vector>

#include "oscar/registry/system_spec.hpp"

namespace oscar::internal {

/// For each module of `system` (by index), the modules that must have been launched before it
/// is: the producers of its inputs. A consumer started together with its producer, or before
/// it, waits in connect_input for the producer's writer (up to 2 s per input); started after
/// it, the writer is usually there. Only producers earlier in a topological order of the wires
/// count: in a cycle the module listed first in the file starts first, so nothing waits for
/// ever. A module's wires to its own kernels are no reason to wait.
std::vector<std::vector<std::size_t>> producers_launched_first(const SystemSpec& system);

}  // namespace oscar::internal
