#pragma once
/// @file SwarmSetup: the system file's `coordinator: swarm:` section (docs/swarm.md, "The live
/// swarm") as the coordinator's swarm side reads it; boot reads it the same way, to refuse a bad
/// one before it starts anything.

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <oscar/swarm.h>

#include "oscar/registry/system_spec.hpp"
#include "oscar/swarm/scheduler.hpp"

namespace oscar::coordinator {

/// The system file's `coordinator: swarm:` section.
struct SwarmSetup {
  struct Robot {
    std::string kernel;  ///< the robot's id
    std::string module;  ///< the module that hosts its pilot kernel
  };
  std::vector<Robot> robots;
  /// The safety monitors the coordinator tells the world (command `world`); left out: every
  /// kernel of type safety_monitor.
  std::vector<Robot> monitors;
  /// The obstacles: `static` polygons (named static[i]) and `dynamic` ones going round a loop in
  /// Unix time ({name, shape, loop}; named dynamic[i] without a name).
  std::vector<SwarmObstacle> world;
  swarm::SchedulerSettings settings;  ///< the present is the system clock
  /// How long a robot may take to answer a proposal before it counts as a NAK.
  std::chrono::milliseconds ack_timeout{500};
  /// How often a request is planned again after robots refused it.
  int replan_attempts = 3;
  /// A robot whose state has not come for this long is taken out of planning like a broken one.
  std::chrono::milliseconds lost_after{2000};
  std::string where;  ///< "file:line" of the section

  /// The section of `system`, or none without one. Robots: `robots: [kernel, ...]`, or every
  /// kernel of type robot_sim when the key is left out.
  /// @throws std::invalid_argument "file:line: ..." naming the key and the rule.
  static std::optional<SwarmSetup> from(const SystemSpec& system);
};

}  // namespace oscar::coordinator
