#include "zero_copy/roudi.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
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

}  // namespace

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
  iox::runtime::PoshRuntime::initRuntime(
      iox::RuntimeName_t(iox::cxx::TruncateToCapacity, name.c_str()));
  joined = true;
  return std::nullopt;
}

bool offered_on_this_host(const std::string& topic, const std::string& type_name) {
  const auto service = internal::service_for(topic, type_name);
  static std::mutex mutex;  // one ServiceDiscovery for the process: it keeps a port with RouDi
  static iox::runtime::ServiceDiscovery* discovery = nullptr;
  std::lock_guard lock(mutex);
  if (!discovery) discovery = new iox::runtime::ServiceDiscovery();  // lives as long as the process
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
