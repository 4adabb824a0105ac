#pragma once
/// @file The coordinator's plan as JSON and as a table (`oscar applets ps`), as a Graphviz picture
/// (`oscar applets graph`), and the request type of its command port `applet` (AppletEvent).

#include <string>

#include <oscar/coordinator.h>
#include <oscar/coordinatorPubSubTypes.h>

#include "oscar/idl_type_info.hpp"

OSCAR_DECLARE_IDL_TYPE(oscar, AppletEvent)

namespace oscar::coordinator {

/// `{"services":{"<service>":{"holders":[..],"access":"shared|exclusive","waiting":[..],
/// "plan":".."}},
/// "applets":[{"name":..,"process":..,"state":..}]}` (one line).
std::string plan_json(const AppletPlan& plan);

/// The plan for people: one line per service (holders, access, waiting), then one per applet.
std::string plan_table(const AppletPlan& plan);

/// DOT text of the plan: applets coloured by state (with their process), services with their
/// access and the plan's holder, who holds and who waits for what, the services' needs and
/// providers (modules or an applet), and a legend.
std::string plan_dot(const AppletPlan& plan);

}  // namespace oscar::coordinator
