#pragma once
// oscar bench swarm --live: the swarm on a booted system (docs/benchmarks-swarm.md, "Live").

#include <nlohmann/json.hpp>

namespace oscar::bench {

/// Boots `robots` robot_sim robots, the coordinator's swarm side and the safety monitor on a free
/// domain, submits jobs at `rate` per second for `seconds`, watches the robots until the last
/// job's window closed, and returns {"robots", "jobs_submitted", "jobs_committed",
/// "jobs_done_in_window", "safety_violations", "submit_to_commit_ms_p50",
/// "submit_to_commit_ms_p99", "naks", "replans", "timeouts", "not_committed" (reason -> count),
/// "coordinator_cpu_percent"}.
/// Progress goes to stderr.
nlohmann::json run_live(int robots, double seconds, double rate);

}  // namespace oscar::bench
