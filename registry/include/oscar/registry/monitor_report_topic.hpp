#pragma once
/// @file The monitors' reports of their module processes (idl/oscar/monitor_report.idl): for
/// oscar-monitor, oscar-registry and the security tool (who may publish it); kept out of
/// oscar/topics.hpp, which nearly everything includes.

#include <oscar/monitor_reportPubSubTypes.h>

#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::topics {

/// The most hosts whose reports a registry's reader keeps at once (one sample per monitor).
inline constexpr int kMonitorReportDepth = 256;

/// oscar/registry/children: each monitor's writer keeps its last report for a registry that
/// starts later (transient-local); the reader keeps the last of every host.
inline TopicSpec<MonitorReport, MonitorReportPubSubType> monitor_children() {
  return {"oscar/registry/children", qos::state_writer(1), qos::state_reader(kMonitorReportDepth)};
}

}  // namespace oscar::topics
