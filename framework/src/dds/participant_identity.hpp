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
#include <optional>
#include <string>

#include <fastdds/rtps/common/Locator.h>
#include <fastdds/rtps/common/GuidPrefix_t.hpp>

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
  /// Writes the participant's GUID prefix into the claim: if this process is killed, a monitor
  /// announces the participant's departure in its name (oscar/dead_participants.hpp).
  void record(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix);

 private:
  std::string path_;
  int fd_ = -1;
};

/// True if `path` still names the file open as `fd`: an orderly release unlinks its claim while
/// holding the lock, so a lock taken just then is on a file nobody else will look at.
bool still_named(int fd, const std::string& path);

/// Claims are files in this directory named "<claim_prefix(domain)><address>_<id>".
inline constexpr const char* kClaimDir = "/dev/shm";
std::string claim_prefix(int domain);

/// RTPS well-known ports (spec 9.6.1.1): PB + DG * domain + d1 + PG * participant.
inline std::uint32_t metatraffic_unicast_port(int domain, int participant) {
  return static_cast<std::uint32_t>(7400 + 250 * domain + 10 + 2 * participant);
}
/// ... and the user unicast port (d3 = 11).
inline std::uint32_t user_unicast_port(int domain, int participant) {
  return metatraffic_unicast_port(domain, participant) + 1;
}

/// A shared-memory locator of this host with a port that no other participant has used.
eprosima::fastrtps::rtps::Locator_t unique_shared_memory_locator();

/// The pid of the process that listens on shared-memory port `port`, if the port is one that
/// unique_shared_memory_locator() made (they carry it); none for Fast DDS's own port numbers.
std::optional<int> shared_memory_port_listener(std::uint32_t port);

}  // namespace oscar::internal
