#pragma once
// SVG pictures for `oscar swarm plan --svg` (world view and s-t diagram).

#include <string>

#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm::tools {

/// World, committed trajectories and jobs seen from above.
std::string world_svg(const Scheduler& scheduler);

/// The s-t diagram of one node's committed trajectory with the forbidden regions of all moving
/// obstacles and other nodes along its path (seed Abb. 4.13).
/// @throws std::invalid_argument on an unknown node.
std::string st_svg(const Scheduler& scheduler, const std::string& node);

}  // namespace oscar::swarm::tools
