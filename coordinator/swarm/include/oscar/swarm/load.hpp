#pragma once
/// @file Load figures of a node over an interval (seed 002 §4.4, eq. 4.22–4.27).

#include <vector>

#include "oscar/swarm/job.hpp"
#include "oscar/swarm/trajectory.hpp"

namespace oscar::swarm {

/// Shares of an interval T, each in [0, 1] (seed §4.4).
struct Load {
  double job = 0;         ///< L_J (4.22): time executing jobs
  double motion = 0;      ///< L_M (4.24): time moving
  double stationary = 0;  ///< L_S (4.25): neither, 1 - L_J - L_M
  double total = 0;       ///< L (4.26): L_J + L_M
  double velocity = 0;    ///< L_v (4.27): distance driven / (v_max · dur(T))
};

/// The load of a node with this trajectory and these jobs over [t0, t1].
/// @throws std::invalid_argument unless t0 < t1, both finite, and max_speed > 0.
Load compute_load(const Trajectory& trajectory, const std::vector<Job>& jobs, double max_speed,
                  double t0, double t1);

}  // namespace oscar::swarm
