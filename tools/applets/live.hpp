#pragma once
// oscar applets run SCENARIO.yaml --live: the scenario's timeline on a booted system, with every
// applet in a process of its own (docs/applets.md, "Live").

#include <chrono>
#include <string>
#include <vector>

#include "oscar/applets/scenario.hpp"

namespace oscar::tools {

struct LiveOptions {
  /// Every time of the scenario (t_ms, advance_ms, deadlines, negotiation answers, the
  /// scheduler's wait limits and context switch) is multiplied by this on the real clock.
  double time_scale = 1.0;
  /// A step's holders are read once the plan has not changed for this long.
  std::chrono::milliseconds settle{200};
};

/// The system file that stands for the scenario's system: one stand-in module per service not
/// provided by an applet, every applet an `event_applet` in a process of its own.
/// @throws std::invalid_argument naming a feature of the scenario that cannot be reproduced live.
std::string live_system_yaml(const applets::Scenario& scenario, const std::string& name,
                             const LiveOptions& options);

/// Boots the system on a free domain (progress on stderr), drives the timeline through the
/// coordinator's command port `applet`, and returns the state after every step as the offline
/// runner does (notes stay empty: the notifications are in the system's log). Ctrl-C (SIGINT,
/// SIGTERM) stops it and shuts the system down.
/// @throws std::invalid_argument for a scenario feature that cannot be reproduced live or an
/// event the coordinator refused ("file:line: ..."); std::runtime_error if the system does not
/// boot or is interrupted.
std::vector<applets::StepResult> run_live(const applets::Scenario& scenario,
                                          const std::string& file, const LiveOptions& options);

}  // namespace oscar::tools
