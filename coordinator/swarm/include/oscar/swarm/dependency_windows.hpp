#pragma once
/// @file Implicit time windows of dependent jobs (seed 002 §4.2.4, eq. 4.6–4.11).

#include <map>
#include <string>
#include <vector>

#include "oscar/swarm/job.hpp"

namespace oscar::swarm {

/// The implicit window of a job: earliest and latest start.
struct ImplicitWindow {
  double earliest_start = 0;  ///< t'_min = α(s) - d (eq. 4.8)
  double latest_start = 0;    ///< t'_max = β(s) (eq. 4.9)
};

/// Computes α/β with margin d_m (eq. 4.10/4.11) for every job. `depends[c]` lists the jobs c waits
/// for; `fixed` gives start times already assigned (t_min = t_max = t, §4.2.4).
/// @throws std::invalid_argument on a dependency naming an unknown job, or a cycle.
std::map<std::string, ImplicitWindow> implicit_windows(
    const std::vector<JobSpec>& jobs,
    const std::map<std::string, std::vector<std::string>>& depends, double margin,
    const std::map<std::string, double>& fixed = {});

/// The jobs in a topological order (dependencies first).
/// @throws std::invalid_argument as implicit_windows.
std::vector<std::string> topological_order(
    const std::vector<JobSpec>& jobs,
    const std::map<std::string, std::vector<std::string>>& depends);

}  // namespace oscar::swarm
