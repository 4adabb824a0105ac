#pragma once
// The Foxglove WebSocket protocol v1 (subprotocol "foxglove.websocket.v1"), the part the bridge
// speaks: the server's JSON messages (serverInfo, advertise, unadvertise, status), the header of
// a binary Message Data frame, and the client's subscribe/unsubscribe. No I/O here.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace oscar::bridge {

inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";

/// A channel as advertised: one DDS topic, its messages CDR, its schema OMG IDL text.
struct ChannelInfo {
  std::uint32_t id = 0;
  std::string topic;
  std::string schema_name;  ///< the IDL type, e.g. "oscar::Bool"
  std::string schema;       ///< self-contained IDL text declaring schema_name
};

enum class StatusLevel { kInfo = 0, kWarning = 1, kError = 2 };

std::string server_info_json(const std::string& name, const std::string& session_id);
std::string advertise_json(const std::vector<ChannelInfo>& channels);
std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids);
std::string status_json(StatusLevel level, const std::string& message);

/// Opcode 0x01, the subscription id (u32 LE) and the receive time (u64 LE, ns); the payload
/// follows in the same frame.
std::array<std::uint8_t, 13> message_data_header(std::uint32_t subscription,
                                                 std::uint64_t receive_ns);

struct Subscribe {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> subscriptions;  ///< id, channel id
};
struct Unsubscribe {
  std::vector<std::uint32_t> subscription_ids;
};
/// A client operation the bridge does not offer (e.g. "advertise" without clientPublish).
struct Unsupported {
  std::string op;
};
using ClientRequest = std::variant<Subscribe, Unsubscribe, Unsupported>;

/// Reads one text message of a client.
/// @throws std::invalid_argument naming what is wrong (not JSON, no "op", a field missing or of
///         the wrong type).
ClientRequest parse_client_message(std::string_view text);

}  // namespace oscar::bridge
