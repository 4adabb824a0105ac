#include "remote_hosts.hpp"

#include <cstdio>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "test_hosts.hpp"  // tests/netns

namespace oscar::bench {

std::string RemoteHosts::unavailable() { return test::TestHosts::unavailable(); }

RemoteHosts::RemoteHosts(UdpSettings udp)
    : udp_(udp), hosts_(std::make_unique<test::TestHosts>(2)) {}

RemoteHosts::~RemoteHosts() = default;

std::vector<std::string> RemoteHosts::on(int i) const {
  auto argv = hosts_->on(i);
  argv.push_back("/usr/bin/env");
  if (udp_.buffer_bytes) {
    argv.push_back(fmt::format("OSCAR_UDP_BUFFER_BYTES={}", *udp_.buffer_bytes));
  }
  if (udp_.max_message_bytes) {
    argv.push_back(fmt::format("OSCAR_UDP_MAX_MESSAGE_BYTES={}", *udp_.max_message_bytes));
  }
  return argv;
}

std::string RemoteHosts::address(int i) const { return hosts_->address(i); }

std::string RemoteHosts::network(int i) const {
  return fmt::format("{{interfaces: [{}], peers: [{}, {}], shared_memory: false}}",
                     hosts_->address(i), hosts_->address(1), hosts_->address(2));
}

LinkCounters RemoteHosts::received(int i) const {
  const auto cmd = fmt::format("ip -n {} -j -s link show 2>/dev/null", hosts_->netns(i));
  std::FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run: " + cmd);
  std::string text;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) text.append(buffer, n);
  if (pclose(pipe) != 0) throw std::runtime_error("failed: " + cmd);
  LinkCounters c;
  for (const auto& link : nlohmann::json::parse(text)) {
    if (link.value("ifname", "") == "lo") continue;
    c.bytes += link["stats64"]["rx"]["bytes"].get<std::uint64_t>();
    c.packets += link["stats64"]["rx"]["packets"].get<std::uint64_t>();
  }
  return c;
}

}  // namespace oscar::bench
