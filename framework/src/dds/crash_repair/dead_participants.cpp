// announce_killed_participants(): the SPDP "disposed" message a participant sends when it is
// deleted, sent in the name of one that was killed (RTPS 2.3, 8.5.3 and 9.4.5.3).
#include "oscar/dead_participants.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <iterator>
#include <set>
#include <sstream>
#include <system_error>

#include "dds/participant_identity.hpp"

namespace oscar {
namespace {

using eprosima::fastrtps::rtps::GuidPrefix_t;

class Message {
 public:
  void bytes(std::initializer_list<std::uint8_t> b) { data_.insert(data_.end(), b); }
  void bytes(const GuidPrefix_t& p) {
    data_.insert(data_.end(), std::begin(p.value), std::end(p.value));
  }
  void u16(std::uint16_t v) {
    bytes({static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)});
  }
  void u32(std::uint32_t v) {
    u16(static_cast<std::uint16_t>(v));
    u16(static_cast<std::uint16_t>(v >> 16));
  }
  const std::vector<std::uint8_t>& data() const { return data_; }

 private:
  std::vector<std::uint8_t> data_;
};

// An RTPS message from `prefix`'s participant: a DATA submessage of its SPDP writer, without
// payload, whose inline QoS names the participant (key hash) and says it is disposed and
// unregistered (status info). Little-endian submessage (flag E), inline QoS (flag Q).
std::vector<std::uint8_t> departure(const GuidPrefix_t& prefix) {
  Message m;
  m.bytes({'R', 'T', 'P', 'S', 2, 3, 0x01, 0x0f});  // protocol 2.3, vendor eProsima
  m.bytes(prefix);
  m.bytes({0x15, 0x03});              // DATA, flags E|Q
  m.u16(52);                          // octets to the next header: the rest below
  m.u16(0);                           // extra flags
  m.u16(16);                          // octets to inline QoS: reader id, writer id, sequence number
  m.bytes({0x00, 0x01, 0x00, 0xc7});  // ENTITYID_SPDP_BUILTIN_RTPSParticipant_READER
  m.bytes({0x00, 0x01, 0x00, 0xc2});  // ENTITYID_SPDP_BUILTIN_RTPSParticipant_WRITER
  // A sequence number above any the participant sent (readers drop what they have seen).
  m.u32(1);       // high
  m.u32(0);       // low
  m.u16(0x0070);  // PID_KEY_HASH: the participant's GUID
  m.u16(16);
  m.bytes(prefix);
  m.bytes({0x00, 0x00, 0x01, 0xc1});  // ENTITYID_RTPSParticipant
  m.u16(0x0071);                      // PID_STATUS_INFO: disposed | unregistered
  m.u16(4);
  m.bytes({0, 0, 0, 0x03});
  m.u16(0x0001);  // PID_SENTINEL
  m.u16(0);
  return m.data();
}

void send_to_all(const std::vector<std::uint8_t>& message, const std::set<std::string>& addresses,
                 int domain, int ids) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return;
  for (const auto& address : addresses) {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    if (inet_pton(AF_INET, address.c_str(), &to.sin_addr) != 1) continue;
    for (int id = 0; id < ids; ++id) {
      to.sin_port =
          htons(static_cast<std::uint16_t>(internal::metatraffic_unicast_port(domain, id)));
      sendto(fd, message.data(), message.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    }
  }
  close(fd);
}

}  // namespace

std::vector<std::string> announce_killed_participants(int domain, const NetworkConfig& network) {
  namespace fs = std::filesystem;
  const auto stem = internal::claim_prefix(domain);
  std::vector<std::string> announced;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(internal::kClaimDir, ec)) {
    const auto name = entry.path().filename().string();
    if (!name.starts_with(stem)) continue;
    const int fd = open(entry.path().c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) continue;
    // A claim is its holder's for as long as the holder lives; one we can lock was left by a
    // process that died.
    if (flock(fd, LOCK_EX | LOCK_NB) != 0 || !internal::still_named(fd, entry.path())) {
      close(fd);
      continue;
    }
    GuidPrefix_t p;
    if (pread(fd, p.value, sizeof p.value, 0) == static_cast<ssize_t>(sizeof p.value)) {
      const auto address = name.substr(stem.size(), name.rfind('_') - stem.size());
      std::set<std::string> to(network.interfaces.begin(), network.interfaces.end());
      to.insert(network.peers.begin(), network.peers.end());
      to.insert(address);
      send_to_all(departure(p), to, domain, network.max_participants_per_host);
      std::ostringstream text;
      text << p;  // Fast DDS's notation: 01.0f.…
      announced.push_back(text.str());
    }
    unlink(entry.path().c_str());  // while holding the lock, as an orderly release does
    close(fd);
  }
  return announced;
}

}  // namespace oscar
