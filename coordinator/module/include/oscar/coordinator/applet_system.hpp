#pragma once
/// @file The applet system of a system file: its `services:` and the `coordinator:` section's
/// applets as the applet scheduler's model (docs/coordinator.md).

#include <oscar/applets/config.hpp>

#include "oscar/registry/system_spec.hpp"

namespace oscar::coordinator {

/// Builds the scheduler's model: one service per `services:` entry (exclusive-only for
/// `access: exclusive`, its `needs:` as dependencies), one applet per configured applet with
/// its bundles, params and fail_stop, and the scheduler options.
/// @throws std::invalid_argument "file:line: ..." on a bad applet or bundle.
applets::SystemConfig applet_system(const SystemSpec& system);

/// The applet scheduler's vocabulary for services and applets added to a running system (what
/// applets::load_addition reads), from the addition's own nodes, so that messages keep their
/// lines; what only the coordinator reads (type, process, host) is left out.
YAML::Node scheduler_doc(const SystemAddition& addition);

/// Checks the system's applets without running them: the model (as applet_system()), and that
/// every applet's type can be made with its params (from a registered type or its plugin on
/// `plugin_path`). What boot does before it starts anything.
/// @throws std::invalid_argument "file:line: applet 'a': ..." naming the applet and the rule.
void check_applets(const SystemSpec& system, const std::vector<std::string>& plugin_path);

}  // namespace oscar::coordinator
