#pragma once
/// @file The topics of the host clock measurement (docs/boot.md, "Clocks"), between the monitors
/// and the registry; the tools read the estimates. Only they include this, not the catalogue
/// every module includes (oscar/topics.hpp).

#include <oscar/host_clockPubSubTypes.h>

#include "oscar/topics.hpp"

namespace oscar::topics {

/// The monitors' probes to the registry (a stream, 16 deep).
TopicSpec<ClockProbe, ClockProbePubSubType> clock_probe();
/// The registry's echoes; each monitor takes the ones with its host and pid (a stream, 16 deep).
TopicSpec<ClockEcho, ClockEchoPubSubType> clock_echo();
/// Each host's latest estimate (state class: a writer per monitor keeps its last one, a reader
/// holds the last 64 of all, so a late reader such as `oscar ps` has every host's at once).
TopicSpec<HostClock, HostClockPubSubType> host_clocks();

}  // namespace oscar::topics
