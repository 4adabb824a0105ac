#include "oscar/shared_memory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <string>
#include <system_error>

namespace oscar {
namespace {

// Fast DDS names its files "fastrtps_<segment>" and "fastrtps_port<port>", each with a lock
// file "<name>_el" that its owner holds with flock() for as long as it lives.
constexpr std::string_view kPrefix = "fastrtps_";
constexpr std::string_view kLockSuffix = "_el";

// True if `lock_file` exists and nobody holds its lock (its owner is gone).
bool abandoned(const std::filesystem::path& lock_file) {
  const int fd = open(lock_file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool free = flock(fd, LOCK_EX | LOCK_NB) == 0;
  if (free) flock(fd, LOCK_UN);
  close(fd);
  return free;
}

}  // namespace

DeadSharedMemorySweeper::DeadSharedMemorySweeper(Clock::duration grace, std::filesystem::path dir)
    : grace_(grace), dir_(std::move(dir)) {}

std::size_t DeadSharedMemorySweeper::sweep(Clock::time_point now) {
  std::map<std::string, Clock::time_point> still_dead;
  std::size_t removed = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    const auto name = entry.path().filename().string();
    if (!name.starts_with(kPrefix) || !name.ends_with(kLockSuffix)) continue;
    if (!abandoned(entry.path())) continue;
    const auto seen = dead_since_.find(name);
    const auto since = seen == dead_since_.end() ? now : seen->second;
    if (now - since < grace_) {
      still_dead.emplace(name, since);
      continue;
    }
    std::error_code ignore;
    const auto owned = name.substr(0, name.size() - kLockSuffix.size());
    if (std::filesystem::remove(dir_ / owned, ignore)) ++removed;
    std::filesystem::remove(dir_ / ("sem." + owned + "_mutex"), ignore);  // a port's lock
    std::filesystem::remove(entry.path(), ignore);
  }
  dead_since_ = std::move(still_dead);  // a name reused by a living owner is forgotten
  return removed;
}

}  // namespace oscar
