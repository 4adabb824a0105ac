#include "dds/udp_tuning.hpp"

#include <cstdlib>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar::internal {
namespace {

// 0 or min..max, written as a plain whole number.
std::uint32_t bytes(const std::string& what, const std::string& text, std::uint32_t min,
                    std::uint32_t max) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || *end != '\0' ||
      (v != 0 && (v < min || v > max))) {
    throw std::invalid_argument(
        fmt::format("{}='{}': expected 0 (the default) or a number of bytes from {} to {}", what,
                    text, min, max));
  }
  return static_cast<std::uint32_t>(v);
}

}  // namespace

std::uint32_t udp_buffer_bytes(const std::string& what, const std::string& text) {
  return bytes(what, text, 65536, 1u << 30);
}

std::uint32_t udp_max_message_bytes(const std::string& what, const std::string& text) {
  return bytes(what, text, 1024, 65500);
}

UdpTuning udp_tuning(const NetworkConfig& net) {
  UdpTuning t{net.udp_buffer_bytes, net.udp_max_message_bytes};
  if (const char* env = std::getenv("OSCAR_UDP_BUFFER_BYTES"); env && *env) {
    t.buffer_bytes = udp_buffer_bytes("OSCAR_UDP_BUFFER_BYTES", env);
  }
  if (const char* env = std::getenv("OSCAR_UDP_MAX_MESSAGE_BYTES"); env && *env) {
    t.max_message_bytes = udp_max_message_bytes("OSCAR_UDP_MAX_MESSAGE_BYTES", env);
  }
  return t;
}

}  // namespace oscar::internal
