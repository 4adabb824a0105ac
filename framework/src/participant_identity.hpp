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

/// `id` of `domain` on `address`, claimed by this process for as long as the object lives (a
/// lock file that the kernel releases when the process dies; removed on an orderly release).
class ParticipantIdClaim {
 public:
  /// Claims it, or returns a claim that holds nothing if another living process holds it.
  ParticipantIdClaim(int domain, const std::string& address, int id);
  ~ParticipantIdClaim();
  ParticipantIdClaim(ParticipantIdClaim&& other) noexcept;
  ParticipantIdClaim& operator=(ParticipantIdClaim&& other) noexcept;
  explicit operator bool() const { return fd_ >= 0; }

 private:
  std::string path_;
  int fd_ = -1;
};

/// A shared-memory locator of this host with a port that no other participant has used.
eprosima::fastrtps::rtps::Locator_t unique_shared_memory_locator();

}  // namespace oscar::internal
