#include "oscar/process_util.hpp"

#include <malloc.h>
#include <pthread.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace oscar {

std::filesystem::path program_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

std::string sibling_program(const std::string& program) {
  return (program_dir() / program).string();
}

std::optional<std::filesystem::path> find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  const std::string dirs = path ? path : "/usr/bin:/bin";  // execvp's default
  for (std::size_t start = 0; start <= dirs.size();) {
    const auto end = std::min(dirs.find(':', start), dirs.size());
    if (end > start) {
      auto candidate = std::filesystem::path(dirs.substr(start, end - start)) / program;
      if (::access(candidate.c_str(), X_OK) == 0 && !std::filesystem::is_directory(candidate))
        return candidate;
    }
    start = end + 1;
  }
  return std::nullopt;
}

namespace {

// True if a thread's /proc stat file says it is neither a zombie nor dead.
bool thread_runs(const std::filesystem::path& stat_file) {
  std::ifstream stat(stat_file);
  std::string line;
  if (!std::getline(stat, line)) return false;
  const auto close = line.rfind(')');  // the command in parentheses may hold anything
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z' &&
         line[close + 2] != 'X';
}

}  // namespace

bool process_lives(pid_t pid) {
  if (pid <= 0) return false;
  std::error_code ec;
  for (const auto& task :
       std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
    if (thread_runs(task.path() / "stat")) return true;
  }
  return false;
}

std::vector<ino_t> inodes_mapped_from(const std::string& path) {
  // Each line: address perms offset device inode path, with " (deleted)" after a removed file.
  std::vector<ino_t> inodes;
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    std::istringstream fields(line);
    std::string address, perms, offset, device, name;
    ino_t inode = 0;
    if (fields >> address >> perms >> offset >> device >> inode >> name && name == path) {
      inodes.push_back(inode);
    }
  }
  return inodes;
}

sigset_t block_stop_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  return signals;
}

bool wait_for_stop(const sigset_t& signals, std::chrono::milliseconds timeout) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
  timespec wait{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  siginfo_t info;
  return sigtimedwait(&signals, &info, &wait) > 0;
}

void keep_cue_memory_in_process() {
  // The largest mmap threshold glibc allows on 64-bit; setting it also stops glibc from moving
  // the threshold (and the trim threshold with it) on its own.
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 64 * 1024 * 1024);
}

void prefault_heap(std::size_t bytes) {
  keep_cue_memory_in_process();
  // Kept at the heap's top once freed: trimmed only beyond this and the usual 64 MB.
  constexpr std::size_t kTrimAbove = std::size_t{64} << 20;
  constexpr std::size_t kMaxTrimThreshold = std::numeric_limits<int>::max();
  mallopt(M_TRIM_THRESHOLD, static_cast<int>(std::min(bytes + kTrimAbove, kMaxTrimThreshold)));
  // In blocks below the mmap threshold, so that they come from the heap and return to it.
  constexpr std::size_t kBlock = std::size_t{1} << 20;
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  std::vector<void*> blocks;
  for (std::size_t touched = 0; touched < bytes; touched += kBlock) {
    auto* block = static_cast<volatile char*>(std::malloc(kBlock));
    if (block == nullptr) break;
    for (std::size_t at = 0; at < kBlock; at += page) block[at] = 0;
    blocks.push_back(const_cast<char*>(block));
  }
  for (auto* block : blocks) std::free(block);
}

void wake_on_time() {
  // Fails only for a negative value (EINVAL), so the result is not checked.
  (void)prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
}

}  // namespace oscar
