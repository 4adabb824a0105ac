#include "oscar/shared_memory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <string>
#include <string_view>
#include <system_error>

#include "../participant_identity.hpp"
#include "oscar/process_util.hpp"

namespace oscar {
namespace {

// Fast DDS names its files "fastrtps_<segment>" and "fastrtps_port<port>", each with a lock
// file "<name>_el" that its owner holds with flock() for as long as it lives.
constexpr std::string_view kPrefix = "fastrtps_";
constexpr std::string_view kLockSuffix = "_el";
// ... and opens a port "fastrtps_port<port>" under the named semaphore "sem.<port file>_mutex".
const std::string kPort = "fastrtps_port", kSemaphore = "sem.", kMutexSuffix = "_mutex";

bool is_port(const std::string& name) {
  return name.size() > kPort.size() && name.starts_with(kPort) &&
         std::all_of(name.begin() + static_cast<std::ptrdiff_t>(kPort.size()), name.end(),
                     [](char c) { return c >= '0' && c <= '9'; });
}

// True if `port` ("fastrtps_port<N>") is the port of another living process. OSCAR's
// participants listen on ports that carry their pid (participant_identity.hpp), and such a port
// goes without its lock file for a moment: Fast DDS takes the port's semaphore, then creates the
// port, then locks it, and it lets go of the lock while it opens the port anew after finding it
// unhealthy. Removed in that moment, the listener would wait on a port nobody could find any
// more, and every sender that opened it later would create another, unheard (the coordinator's
// commands to a camera went nowhere for good while a monitor of another system shut down). The
// sweeping process's own ports are its deleted participants' (a live one holds its lock).
bool listener_lives(const std::string& port) {
  const std::string_view digits = std::string_view(port).substr(kPort.size());
  std::uint32_t number = 0;
  if (std::from_chars(digits.data(), digits.data() + digits.size(), number).ec != std::errc{}) {
    return false;
  }
  const auto pid = internal::shared_memory_port_listener(number);
  return pid && *pid != getpid() && process_lives(*pid);
}

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

DeadSharedMemorySweeper::DeadSharedMemorySweeper(Clock::duration grace, std::filesystem::path dir,
                                                 std::function<bool(const std::string&)> only)
    : grace_(grace), dir_(std::move(dir)), only_(std::move(only)) {}

std::size_t DeadSharedMemorySweeper::sweep(Clock::time_point now) {
  std::map<std::string, Clock::time_point> still_dead;
  // True once `name` has been seen dead for the grace period.
  const auto due = [&](const std::string& name) {
    const auto seen = dead_since_.find(name);
    const auto since = seen == dead_since_.end() ? now : seen->second;
    if (now - since >= grace_) return true;
    still_dead.emplace(name, since);
    return false;
  };
  const auto exists = [&](const std::string& name) {
    std::error_code ignore;
    return std::filesystem::exists(dir_ / name, ignore);
  };
  std::size_t removed = 0;
  std::error_code ec, ignore;
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    const auto name = entry.path().filename().string();
    if (only_ && !only_(name)) continue;
    if (name.starts_with(kPrefix) && name.ends_with(kLockSuffix)) {
      // A segment or port whose owner is gone.
      const auto owned = name.substr(0, name.size() - kLockSuffix.size());
      if (!abandoned(entry.path()) || (is_port(owned) && listener_lives(owned)) || !due(name)) {
        continue;
      }
      if (std::filesystem::remove(dir_ / owned, ignore)) ++removed;
      std::filesystem::remove(dir_ / (kSemaphore + owned + kMutexSuffix), ignore);
      std::filesystem::remove(entry.path(), ignore);
    } else if (is_port(name)) {
      // A port that no reader owns, exclusively ("_el") or shared ("_sl", Fast DDS's multicast
      // ports): a sender created it while sending to a participant that had died.
      if (exists(name + std::string(kLockSuffix)) || exists(name + "_sl") || listener_lives(name) ||
          !due(name)) {
        continue;
      }
      if (std::filesystem::remove(entry.path(), ignore)) ++removed;
      std::filesystem::remove(dir_ / (kSemaphore + name + kMutexSuffix), ignore);
    } else if (name.starts_with(kSemaphore) && name.ends_with(kMutexSuffix) &&
               is_port(name.substr(kSemaphore.size(),
                                   name.size() - kSemaphore.size() - kMutexSuffix.size()))) {
      // A port's lock, left behind by its port (Fast DDS never removes them).
      const auto port =
          name.substr(kSemaphore.size(), name.size() - kSemaphore.size() - kMutexSuffix.size());
      if (exists(port) || listener_lives(port) || !due(name)) continue;
      if (std::filesystem::remove(entry.path(), ignore)) ++removed;
    }
  }
  dead_since_ = std::move(still_dead);  // a name reused by a living owner is forgotten
  return removed;
}

std::size_t remove_files_of_dead_processes(int domain, const std::filesystem::path& dir) {
  auto removed = DeadSharedMemorySweeper(std::chrono::seconds(0), dir).sweep();
  const auto claims = internal::claim_prefix(domain);
  std::error_code ec, ignore;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const auto name = entry.path().filename().string();
    if (name.starts_with(claims) && abandoned(entry.path()) &&
        std::filesystem::remove(entry.path(), ignore)) {
      ++removed;
    }
  }
  return removed;
}

namespace {
// Whether the file at `path` (its stat in `now`, if `there`) is one of those in `mapped`.
bool is_mapped(const std::vector<ino_t>& mapped, bool there, const struct stat& now) {
  return there && std::find(mapped.begin(), mapped.end(), now.st_ino) != mapped.end();
}
}  // namespace

bool maps_current_port_file(std::uint32_t port, const std::filesystem::path& dir) {
  const auto path = (dir / (kPort + std::to_string(port))).string();
  const auto mapped = inodes_mapped_from(path);
  struct stat now {};
  const bool there = ::stat(path.c_str(), &now) == 0;
  return mapped.empty() || is_mapped(mapped, there, now);
}

PortFileWatch::PortFileWatch(std::optional<std::uint32_t> port, std::filesystem::path dir)
    : port_(port), dir_(std::move(dir)) {}

std::optional<std::string> PortFileWatch::lost() {
  if (!port_) return std::nullopt;
  const auto path = (dir_ / (kPort + std::to_string(*port_))).string();
  struct stat now {};
  const bool there = ::stat(path.c_str(), &now) == 0;
  // While the file at the path is the one found mapped at the last look, nothing changed:
  // /proc/self/maps (hundreds of lines in a module) is read only when the file did.
  if (there && confirmed_ && now.st_ino == *confirmed_) {
    lost_looks_ = 0;
    return std::nullopt;
  }
  const auto mapped = inodes_mapped_from(path);
  confirmed_.reset();
  if (is_mapped(mapped, there, now)) confirmed_ = now.st_ino;
  if (mapped.empty() || confirmed_) {
    lost_looks_ = 0;
    return std::nullopt;
  }
  if (++lost_looks_ < kLooks) return std::nullopt;
  return path;
}

}  // namespace oscar
