#pragma once
// Internal: which participant id and which shared-memory port a new DDS participant takes.
//
// - Ids: two processes starting at once must not take the same id (the second one's ports would
//   be moved by Fast DDS behind our back). An id is claimed with a lock file that the kernel
//   releases when the process ends, however it ends.
// - Shared-memory port: Fast DDS would name it after the participant id. A killed process's port
//   stays mapped in every process that sent to it, and Fast DDS notices a dead port only through
//   a watchdog that does not see every death; a new participant taking the same id (and so the
//   same port) was then unreachable for seconds (`oscar bench restart`). So every participant
//   listens on a port of its own, never used before: derived from the pid.

#include <cstdint>
#include <string>

#include <fastdds/rtps/common/Locator.h>

namespace oscar::internal {

/// Claims `id` of `domain` on `address` for this process; returns the held lock's file
/// descriptor, or -1 if another living process holds it. close() releases it.
int claim_participant_id(int domain, const std::string& address, int id);

/// A shared-memory locator of this host with a port that no other participant has used.
eprosima::fastrtps::rtps::Locator_t unique_shared_memory_locator();

}  // namespace oscar::internal
