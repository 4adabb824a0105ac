#pragma once
/// @file The outcome of a scheduler operation (seed 002 §5.2 ScheduleResult).

#include <cstdint>
#include <string>
#include <vector>

#include "oscar/swarm/job.hpp"

namespace oscar::swarm {

/// Identifies a transaction (seed §4.2.7); 0 means none.
using TransactionId = std::uint64_t;

/// What a schedule/unschedule/reschedule did. A failure is a regular outcome, not an exception:
/// `ok` is false, `reason` says why and the schedule is unchanged.
struct ScheduleResult {
  bool ok = false;
  std::string reason;
  TransactionId transaction = 0;  ///< the open transaction holding the change (if ok)
  std::vector<Job> jobs;          ///< the jobs scheduled by this operation
};

}  // namespace oscar::swarm
