#pragma once
// A test process of its own mount namespace, with fresh /dev/shm and /tmp (tmpfs): for tests that
// start an iceoryx RouDi, whose names there are fixed (/dev/shm/iceoryx_mgmt, /tmp/roudi), so that
// they run in parallel with each other and leave no files behind. Needs root; the tests skip with
// the reason otherwise.
#include <sched.h>
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace oscar::test {

// Entered before main() (and before any thread), when a test binary includes this header: empty
// if that worked, else why not.
inline const std::string kNoPrivateTmp = [] {
  if (::unshare(CLONE_NEWNS) != 0) return std::string("unshare(CLONE_NEWNS): ") + strerror(errno);
  if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0)
    return std::string("making / private: ") + strerror(errno);
  for (const char* dir : {"/dev/shm", "/tmp"})
    if (::mount("tmpfs", dir, "tmpfs", 0, "size=256m") != 0)
      return std::string("tmpfs on ") + dir + ": " + strerror(errno);
  return std::string();
}();

}  // namespace oscar::test
