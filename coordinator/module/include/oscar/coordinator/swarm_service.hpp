#pragma once
/// @file SwarmService: the coordinator's swarm side (docs/swarm.md, "The live swarm"). Jobs arrive
/// on oscar/swarm/request; the swarm planner (oscar::swarm::Scheduler) places them in a
/// transaction; each robot the transaction changes gets its new trajectory sections on its
/// pilot's command port `propose` and answers ACK or NAK; when every robot concerned acknowledged,
/// the transaction commits (and the robots hear `commit`), else it aborts (`abort`) and the request
/// is planned again (seed 002 §4.2.7). Robots are kernels publishing RobotState cues; one that
/// breaks down leaves planning and its jobs are placed on others.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <oscar/swarm.h>

#include "oscar/dds_participant.hpp"
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
  swarm::World world;
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

class SwarmService {
 public:
  /// Nothing runs before start().
  SwarmService(SwarmSetup setup, DdsParticipant& participant);
  ~SwarmService();
  SwarmService(const SwarmService&) = delete;
  SwarmService& operator=(const SwarmService&) = delete;

  void start();
  void stop();

  /// What the service publishes on oscar/swarm/status, as it stands now.
  SwarmStatus status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace oscar::coordinator
