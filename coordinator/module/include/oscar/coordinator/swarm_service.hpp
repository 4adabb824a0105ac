#pragma once
/// @file SwarmService: the coordinator's swarm side (docs/swarm.md, "The live swarm"). Jobs arrive
/// on oscar/swarm/request; the swarm planner (oscar::swarm::Scheduler) places them in a
/// transaction; each robot the transaction changes gets its new trajectory sections on its
/// pilot's command port `propose` and answers ACK or NAK; when every robot concerned acknowledged,
/// the transaction commits (and the robots hear `commit`), else it aborts (`abort`) and the request
/// is planned again (seed 002 §4.2.7). Robots are kernels publishing RobotState cues; one that
/// breaks down leaves planning and its jobs are placed on others.

#include <memory>

#include <oscar/swarm.h>

#include "oscar/coordinator/swarm_setup.hpp"
#include "oscar/dds_participant.hpp"

namespace oscar::coordinator {

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
