#pragma once
/// @file A robot's trajectory as YAML text: how a pilot answers command `committed` with its
/// committed plan (idl/oscar/swarm.idl, CommittedPlanQuery), in the form `oscar config ...
/// command` takes a Trajectory: a struct is a map of its members by name.

#include <string>

#include "oscar/swarm_types.hpp"

namespace oscar {

/// `t` as one line of YAML in flow style, every member written, times as integers (ns) and
/// places as shortest round-trip decimals, so trajectory_from_yaml gives `t` back exactly.
std::string to_yaml(const Trajectory& t);

/// A Trajectory from YAML; a member left out takes its IDL default (0, false, "", empty).
/// @throws std::invalid_argument naming the member (e.g. "sections[0].waypoints[2].t_ns") and
///         the rule: no YAML, not a map or a list where one belongs, a value that is no number of
///         the member's type, an unknown member.
Trajectory trajectory_from_yaml(const std::string& text);

}  // namespace oscar
