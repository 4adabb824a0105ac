// OrphanedPortLocks: which of Fast DDS's port semaphores lost their holder, judged from the
// semaphore itself and from who has it mapped (/proc/<pid>/maps).
#include <fcntl.h>
#include <semaphore.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "oscar/shared_memory.hpp"

namespace oscar {
namespace {

namespace fs = std::filesystem;
constexpr const char* kSemaphoreDir = "/dev/shm";  // where glibc keeps named semaphores
constexpr std::string_view kSemaphore = "sem.";
constexpr std::string_view kMutexSuffix = "_mutex";

// glibc keeps a semaphore in one 64-bit word: the value in the low half, the number of threads
// blocked in sem_wait/sem_timedwait in the high half.
static_assert(sizeof(void*) == 8, "the layout of glibc's semaphores read here is the 64-bit one");
struct SemaphoreWord {
  std::uint32_t value = 1;
  std::uint32_t waiters = 0;
};

std::optional<SemaphoreWord> read_word(const fs::path& file) {
  const int fd = open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::uint64_t data = 0;
  const auto n = pread(fd, &data, sizeof data, 0);
  close(fd);
  if (n != sizeof data) return std::nullopt;
  return SemaphoreWord{static_cast<std::uint32_t>(data), static_cast<std::uint32_t>(data >> 32)};
}

bool read_all(const fs::path& file, std::string& out) {
  const int fd = open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  char buf[65536];
  for (ssize_t n; (n = read(fd, buf, sizeof buf)) > 0;)
    out.append(buf, static_cast<std::size_t>(n));
  close(fd);
  return true;
}

// How a memory map names a file: "<major>:<minor> <inode>", in hex and decimal.
std::string map_identity(const fs::path& file) {
  struct stat st {};
  if (stat(file.c_str(), &st) != 0) return {};
  return fmt::format("{:02x}:{:02x} {}", major(st.st_dev), minor(st.st_dev), st.st_ino);
}

// How many processes have each of `files` mapped. Matched by device and inode, not by path: the
// process that created a semaphore maps it under a temporary name (glibc links it into place).
std::map<std::string, unsigned> processes_mapping(const std::vector<std::string>& files) {
  std::map<std::string, std::string> by_identity;  // identity -> file
  for (const auto& f : files) by_identity.emplace(map_identity(f), f);
  by_identity.erase(std::string{});
  std::map<std::string, unsigned> count;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/proc", ec)) {
    const auto pid = entry.path().filename().string();
    if (pid.empty() || !std::all_of(pid.begin(), pid.end(), ::isdigit)) continue;
    std::string maps;
    // Gone, or a process whose memory we may not see (another user's, or not dumpable): not one
    // that Fast DDS processes of ours share locks with.
    if (!read_all(entry.path() / "maps", maps)) continue;
    std::set<std::string> seen;
    std::istringstream lines(maps);
    for (std::string range, perms, offset, dev, inode, rest;
         lines >> range >> perms >> offset >> dev >> inode;) {
      std::getline(lines, rest);
      if (const auto it = by_identity.find(dev + " " + inode); it != by_identity.end()) {
        seen.insert(it->second);
      }
    }
    for (const auto& f : seen) ++count[f];
  }
  return count;
}

}  // namespace

OrphanedPortLocks::OrphanedPortLocks(std::string prefix) : prefix_(std::move(prefix)) {}

std::size_t OrphanedPortLocks::note_taken() {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(kSemaphoreDir, ec)) {
    const auto file = entry.path().filename().string();
    if (!file.starts_with(kSemaphore) || !file.ends_with(kMutexSuffix)) continue;
    const auto name = file.substr(kSemaphore.size());
    if (!name.starts_with(prefix_)) continue;
    const auto word = read_word(entry.path());
    if (word && word->value == 0 && std::find(taken_.begin(), taken_.end(), name) == taken_.end())
      taken_.push_back(name);
  }
  return taken_.size();
}

std::vector<std::string> OrphanedPortLocks::release() {
  std::vector<std::string> released;
  if (taken_.empty()) return released;
  std::vector<std::string> still_taken, files;
  std::map<std::string, SemaphoreWord> words;
  for (const auto& name : taken_) {
    const auto file = (fs::path(kSemaphoreDir) / (std::string(kSemaphore) + name)).string();
    const auto word = read_word(file);
    if (!word || word->value != 0) continue;  // given back (or gone): its holder was alive
    still_taken.push_back(name);
    files.push_back(file);
    words[file] = *word;
  }
  taken_ = std::move(still_taken);
  if (taken_.empty()) return released;
  const auto mapping = processes_mapping(files);
  for (std::size_t i = 0; i < taken_.size();) {
    const auto& file = files[i];
    const auto it = mapping.find(file);
    const unsigned mappers = it == mapping.end() ? 0 : it->second;
    // A holder has the semaphore mapped and does not wait for it; so if no more processes map it
    // than threads wait for it, the holder is gone. Confirm the word did not move meanwhile.
    const auto now = read_word(file);
    if (mappers > words[file].waiters || !now || now->value != 0) {
      ++i;
      continue;
    }
    if (sem_t* s = sem_open(("/" + taken_[i]).c_str(), 0); s != SEM_FAILED) {
      sem_post(s);
      sem_close(s);
      released.push_back(taken_[i]);
    }
    taken_.erase(taken_.begin() + static_cast<std::ptrdiff_t>(i));
    files.erase(files.begin() + static_cast<std::ptrdiff_t>(i));
  }
  return released;
}

}  // namespace oscar
