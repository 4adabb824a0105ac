#include "dds/participant_identity.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <utility>

#include <fastrtps/utils/IPFinder.h>
#include <fastrtps/utils/md5.h>
#include <fmt/format.h>

namespace oscar::internal {
using eprosima::fastrtps::rtps::IPFinder;
using eprosima::fastrtps::rtps::Locator_t;
using eprosima::fastrtps::rtps::LocatorList_t;

bool still_named(int fd, const std::string& path) {
  struct stat held {
  }, named{};
  return fstat(fd, &held) == 0 && stat(path.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
         held.st_dev == named.st_dev;
}

std::string claim_prefix(int domain) { return fmt::format("oscar_participant_d{}_", domain); }

ParticipantIdClaim::ParticipantIdClaim(int domain, const std::string& address, int id)
    : path_(fmt::format("{}/{}{}_{}", kClaimDir, claim_prefix(domain), address, id)) {
  for (;;) {
    const int fd = open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) return;
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      close(fd);
      return;
    }
    // The holder before us may have removed the file between our open and our lock: then the
    // claim is tried again.
    if (still_named(fd, path_)) {
      fd_ = fd;
      return;
    }
    close(fd);
  }
}

void ParticipantIdClaim::record(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  if (fd_ < 0) return;
  if (pwrite(fd_, prefix.value, sizeof prefix.value, 0) != sizeof prefix.value) {
    [[maybe_unused]] const int ignored = ftruncate(fd_, 0);  // no partial prefix is taken for one
  }
}

ParticipantIdClaim::~ParticipantIdClaim() {
  if (fd_ < 0) return;
  unlink(path_.c_str());  // while still holding the lock: see the constructor
  close(fd_);
}

ParticipantIdClaim::ParticipantIdClaim(ParticipantIdClaim&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)) {}

ParticipantIdClaim& ParticipantIdClaim::operator=(ParticipantIdClaim&& other) noexcept {
  if (this != &other) {
    this->~ParticipantIdClaim();
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

namespace {

// Above every RTPS well-known port; pids are below 2^22, 16 participants per process.
constexpr std::uint32_t kOwnPortsFrom = 1u << 24;

// Fast DDS sends by shared memory only to locators of its own host, which it recognises by a
// 16-bit host id in the locator's address: the MD5 digest of the host's IPv4 addresses (in the
// order its IPFinder lists them), folded into 16 bits; 127, 1 if it has none.
std::uint16_t fast_dds_host_id() {
  LocatorList_t addresses;
  IPFinder::getIP4Address(&addresses);
  if (addresses.empty()) return 127 | 1 << 8;
  MD5 md5;
  for (const auto& a : addresses) md5.update(a.address, sizeof a.address);
  md5.finalize();
  std::uint16_t id = 0;
  for (std::size_t i = 0; i < sizeof md5.digest; i += 2) {
    id ^= static_cast<std::uint16_t>(md5.digest[i] << 8 | md5.digest[i + 1]);
  }
  return id;
}

}  // namespace

Locator_t unique_shared_memory_locator() {
  static const std::uint16_t host = fast_dds_host_id();
  static std::atomic<std::uint32_t> created{0};
  Locator_t l;
  l.kind = LOCATOR_KIND_SHM;
  l.port = kOwnPortsFrom + (static_cast<std::uint32_t>(getpid()) << 4) + created++ % 16;
  l.address[0] = 'U';  // unicast
  l.address[1] = static_cast<eprosima::fastrtps::rtps::octet>(host);
  l.address[2] = static_cast<eprosima::fastrtps::rtps::octet>(host >> 8);
  return l;
}

std::optional<int> shared_memory_port_listener(std::uint32_t port) {
  if (port < kOwnPortsFrom) return std::nullopt;
  return static_cast<int>((port - kOwnPortsFrom) >> 4);
}

}  // namespace oscar::internal
