#include "zero_copy/roudi.hpp"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <stop_token>
#include <thread>

#include <fmt/format.h>
#include <iceoryx_hoofs/cxx/generic_raii.hpp>
#include <iceoryx_hoofs/error_handling/error_handling.hpp>
#include <iceoryx_posh/runtime/posh_runtime.hpp>
#include <iceoryx_posh/runtime/service_discovery.hpp>

#include "oscar/process_util.hpp"
#include "zero_copy/service.hpp"

namespace oscar::zero_copy {
namespace {

// iceoryx 2.0 on Linux: unix datagram sockets under IOX_UDS_SOCKET_PATH_PREFIX, RouDi's named
// IPC_CHANNEL_ROUDI_NAME.
std::string roudi_socket() {
  return std::string(iox::platform::IOX_UDS_SOCKET_PATH_PREFIX) +
         iox::roudi::IPC_CHANNEL_ROUDI_NAME;
}

std::string management_segment() { return std::string("/dev/shm/") + iox::roudi::SHM_NAME; }

// The inode of file `path`; 0 if there is none.
unsigned long inode_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? st.st_ino : 0;
}

// How this process ends when iceoryx cannot go on (end_process_on_iceoryx_error()).
struct Ending {
  int exit_code = 1;
  std::function<void(const std::string& what, bool ending)> say;
};
std::mutex ending_mutex;
Ending ending;  // under ending_mutex

// Ends the process at once, saying `why` through end_process_on_iceoryx_error()'s `say` (or on
// stderr if none was given) with the exit code given there (else 1).
[[noreturn]] void end_process(const std::string& why) {
  Ending e;
  {
    std::lock_guard lock(ending_mutex);
    e = ending;
  }
  const auto what = fmt::format("{}: the process ends with exit code {}", why, e.exit_code);
  if (e.say) {
    e.say(what, true);
  } else {
    std::fprintf(stderr, "%s\n", what.c_str());
  }
  std::fflush(nullptr);
  std::_Exit(e.exit_code);
}

// The inode of the socket of the RouDi this process joined; 0 before it joined.
std::atomic<unsigned long> joined_socket_inode{0};

}  // namespace

AwaitingRoudi::AwaitingRoudi(std::string asking)
    : asking_(std::move(asking)),
      socket_(roudi_socket()),
      inode_(joined_socket_inode != 0 ? joined_socket_inode.load() : inode_of(socket_)),
      thread_([this](std::stop_token stop) { watch(stop); }) {}

void AwaitingRoudi::watch(std::stop_token stop) {
  std::mutex mutex;
  std::condition_variable_any wake;
  std::unique_lock lock(mutex);
  for (;;) {
    wake.wait_for(lock, stop, std::chrono::milliseconds(5), [] { return false; });
    if (stop.stop_requested()) return;
    const auto now = inode_of(socket_);
    if (now == inode_ && roudi_running()) continue;
    end_process(fmt::format("the RouDi this process {} went away before it answered ({} {})",
                            asking_, socket_,
                            now == 0        ? "is gone"
                            : now != inode_ ? "is another socket"
                                            : "takes no message"));
  }
}

bool roudi_running() {
  const auto path = roudi_socket();
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.size() >= sizeof(address.sun_path)) return false;
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM, 0);
  if (fd < 0) return false;
  // A datagram socket connects only to a bound one: a socket file left by a dead RouDi refuses.
  const bool listening =
      ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  ::close(fd);
  return listening;
}

std::optional<std::string> join_roudi(const std::string& name) {
  if (name.empty() || name.size() > iox::RuntimeName_t::capacity() || name.find('/') != name.npos)
    throw std::invalid_argument(
        fmt::format("zero-copy runtime name '{}': 1 to {} characters without '/'", name,
                    iox::RuntimeName_t::capacity()));
  static std::mutex mutex;
  static bool joined = false;
  std::lock_guard lock(mutex);
  if (joined) return std::nullopt;
  if (!roudi_running()) {
    if (!find_on_path("iox-roudi"))
      return fmt::format(
          "iox-roudi is not installed (Debian package iceoryx) and no RouDi listens "
          "on {}",
          roudi_socket());
    return fmt::format("no RouDi runs on this host (nothing listens on {}; start iox-roudi)",
                       roudi_socket());
  }
  {
    const AwaitingRoudi awaiting("was registering with");
    iox::runtime::PoshRuntime::initRuntime(
        iox::RuntimeName_t(iox::cxx::TruncateToCapacity, name.c_str()));
    joined_socket_inode = awaiting.socket_inode();
  }
  joined = true;
  return std::nullopt;
}

void end_process_on_iceoryx_error(int exit_code,
                                  std::function<void(const std::string&, bool ending)> say) {
  static std::mutex mutex;
  static std::optional<iox::cxx::GenericRAII> handler;  // puts iceoryx's own back at exit
  std::lock_guard lock(mutex);
  {
    std::lock_guard ending_lock(ending_mutex);
    ending = Ending{exit_code, say};
  }
  handler.reset();
  handler.emplace(iox::ErrorHandler::setTemporaryErrorHandler(
      [say = std::move(say)](const iox::Error error, const std::function<void()>& callback,
                             const iox::ErrorLevel level) {
        if (callback) callback();
        const char* name = iox::ErrorHandler::toString(error);
        if (level == iox::ErrorLevel::MODERATE) {
          say(fmt::format("iceoryx reports {} and goes on", name), false);
          return;
        }
        // The caller cannot go on (a severe error hands it a null port): end before it does.
        end_process(fmt::format(
            "iceoryx reports {}, a {} error it cannot go on from (most often the RouDi this "
            "process joined no longer answers)",
            name, level == iox::ErrorLevel::FATAL ? "fatal" : "severe"));
      }));
}

RoudiWatch::RoudiWatch(std::function<void(const std::string& why)> gone,
                       std::chrono::milliseconds period)
    : gone_(std::move(gone)), period_(period), joined_inode_([] {
        const auto mapped = inodes_mapped_from(management_segment());
        return mapped.empty() ? 0 : mapped.front();
      }()) {
  if (joined_inode_ == 0)
    throw std::runtime_error(
        fmt::format("this process maps no {}: it joined no RouDi", management_segment()));
  thread_ = std::thread([this] { watch(); });
}

RoudiWatch::~RoudiWatch() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void RoudiWatch::watch() {
  const auto segment = management_segment();
  std::unique_lock lock(mutex_);
  while (!wake_.wait_for(lock, period_, [this] { return stopping_; })) {
    struct stat now {};
    const bool there = ::stat(segment.c_str(), &now) == 0;
    if (there && now.st_ino == joined_inode_) continue;
    // A new RouDi makes its segment before it listens: a process started again before that
    // would find no RouDi and stay on DDS.
    if (there && !roudi_running()) continue;
    lock.unlock();
    gone_(there ? fmt::format("the RouDi it joined is gone and another runs ({} is a new segment): "
                              "its zero-copy cues would reach no process started since",
                              segment)
                : fmt::format("the RouDi it joined is gone ({} was removed)", segment));
    return;
  }
}

bool offered_on_this_host(const std::string& topic, const std::string& type_name) {
  const auto service = internal::service_for(topic, type_name);
  static std::mutex mutex;  // one ServiceDiscovery for the process: it keeps a port with RouDi
  static iox::runtime::ServiceDiscovery* discovery = nullptr;
  std::lock_guard lock(mutex);
  if (!discovery) {
    const AwaitingRoudi awaiting("asked for a service discovery port");
    discovery = new iox::runtime::ServiceDiscovery();  // lives as long as the process
  }
  bool found = false;
  discovery->findService(
      service.getServiceIDString(), service.getInstanceIDString(), service.getEventIDString(),
      [&](const iox::capro::ServiceDescription&) { found = true; },
      iox::popo::MessagingPattern::PUB_SUB);
  return found;
}

std::string zero_copy_topic(int domain, const std::string& topic) {
  return fmt::format("{}/{}", domain, topic);
}

}  // namespace oscar::zero_copy
