#include "dds/udp_tuning.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace oscar::internal {
namespace {

// The variable's value, 0 or min..max; `fallback` if it is unset or empty.
std::uint32_t bytes_from_env(const char* name, std::uint32_t fallback, std::uint32_t min,
                             std::uint32_t max) {
  const char* env = std::getenv(name);
  if (!env || !*env) return fallback;
  const std::string text = env;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (text.find_first_not_of("0123456789") != std::string::npos || *end != '\0' ||
      (v != 0 && (v < min || v > max))) {
    throw std::invalid_argument(
        fmt::format("{}='{}': expected 0 (the default) or a number of bytes from {} to {}", name,
                    text, min, max));
  }
  return static_cast<std::uint32_t>(v);
}

}  // namespace

UdpTuning udp_tuning_from_env() {
  UdpTuning t;
  t.buffer_bytes = bytes_from_env("OSCAR_UDP_BUFFER_BYTES", t.buffer_bytes, 65536, 1u << 30);
  t.max_message_bytes =
      bytes_from_env("OSCAR_UDP_MAX_MESSAGE_BYTES", t.max_message_bytes, 1024, 65500);
  return t;
}

}  // namespace oscar::internal
