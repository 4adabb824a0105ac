// release_mutexes_of_dead_threads(): finds glibc's process-shared mutexes in Fast DDS's port
// segments whose owner thread is gone, and unlocks them as glibc's unlock would.
#include <fcntl.h>
#include <linux/futex.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <system_error>

#include "oscar/shared_memory.hpp"

namespace oscar {
namespace {

// The start of glibc's pthread_mutex_t (x86-64 and aarch64, struct __pthread_mutex_s).
struct GlibcMutex {
  int lock;             // 0 free, 1 locked, 2 locked with waiters
  unsigned int count;   // recursion depth of a recursive mutex
  int owner;            // thread id of the holder
  unsigned int nusers;  // lock() calls not yet unlocked
  int kind;             // type | PTHREAD_MUTEX_PSHARED_BIT
};
static_assert(sizeof(pthread_mutex_t) == 40 && alignof(pthread_mutex_t) == 8,
              "the layout of glibc's mutexes read here is the 64-bit one");
constexpr int kProcessShared = 128;    // glibc's PTHREAD_MUTEX_PSHARED_BIT
constexpr int kMaxThreadId = 1 << 22;  // the kernel's PID_MAX_LIMIT

bool thread_exists(int tid) { return kill(tid, 0) == 0 || errno == EPERM; }

// Boost's interprocess mutexes are normal or recursive ones, process-shared. The scan looks at
// every aligned word of a segment, and Fast DDS's ring cells and allocator nodes hold small
// numbers that can take the shape of a locked mutex; but glibc's lock() counts its holder in
// `nusers`, so a "mutex" that is locked with no user is data, and is not written to.
bool held_by_dead_thread(const GlibcMutex& m) {
  const bool normal = m.kind == kProcessShared && m.count == 0;
  const bool recursive = m.kind == (kProcessShared | PTHREAD_MUTEX_RECURSIVE) && m.count >= 1;
  return (m.lock == 1 || m.lock == 2) && (normal || recursive) && m.owner > 0 &&
         m.owner < kMaxThreadId && m.nusers >= 1 && !thread_exists(m.owner);
}

// What glibc's unlock does for these kinds: forget the owner, free the lock word, wake waiters
// (a shared futex: they wait in other processes).
void unlock(GlibcMutex& m) {
  m.count = 0;
  m.owner = 0;
  if (m.nusers > 0) --m.nusers;
  std::atomic_ref<int>(m.lock).store(0, std::memory_order_release);
  syscall(SYS_futex, &m.lock, FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0);
}

// Releases the dead threads' mutexes in one file; returns how many.
int release_in(const std::filesystem::path& file) {
  const int fd = open(file.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return 0;
  struct stat st {};
  int released = 0;
  if (fstat(fd, &st) == 0 && st.st_size >= static_cast<off_t>(sizeof(pthread_mutex_t))) {
    const auto size = static_cast<std::size_t>(st.st_size);
    void* map = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (map != MAP_FAILED) {
      auto* bytes = static_cast<char*>(map);
      for (std::size_t at = 0; at + sizeof(pthread_mutex_t) <= size;
           at += alignof(pthread_mutex_t)) {
        auto* m = reinterpret_cast<GlibcMutex*>(bytes + at);
        if (held_by_dead_thread(*m)) {
          unlock(*m);
          ++released;
        }
      }
      munmap(map, size);
    }
  }
  close(fd);
  return released;
}

}  // namespace

std::vector<std::string> release_mutexes_of_dead_threads(const std::filesystem::path& dir,
                                                         const std::string& prefix) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const auto name = entry.path().filename().string();
    // The port segment itself, not its lock files ("_el", "_sl") or its semaphore.
    if (!name.starts_with(prefix) || name.find('_', prefix.size()) != std::string::npos) continue;
    if (release_in(entry.path()) > 0) files.push_back(name);
  }
  return files;
}

}  // namespace oscar
