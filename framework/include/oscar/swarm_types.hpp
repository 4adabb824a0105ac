#pragma once
/// @file The live swarm's types (idl/oscar/swarm.idl): robot states and safety violations as
/// cues, trajectories and decisions as commands of a robot's pilot (docs/swarm.md).

#include <oscar/swarm.h>
#include <oscar/swarmPubSubTypes.h>

#include "oscar/cue.hpp"
#include "oscar/idl_type_info.hpp"

OSCAR_DECLARE_CUE_TYPE(oscar, RobotState)
OSCAR_DECLARE_CUE_TYPE(oscar, SafetyViolation)
OSCAR_DECLARE_IDL_TYPE(oscar, Trajectory)
OSCAR_DECLARE_IDL_TYPE(oscar, TransactionDecision)
OSCAR_DECLARE_IDL_TYPE(oscar, CommittedPlanQuery)
OSCAR_DECLARE_IDL_TYPE(oscar, SwarmWorld)
