#pragma once
// The Foxglove WebSocket protocol v1 (subprotocol "foxglove.websocket.v1"), the part the bridge
// speaks: the server's JSON messages (serverInfo, advertise, unadvertise, status,
// advertiseServices, serviceCallFailure), the header of a binary Message Data frame, a Service
// Call Response frame, and the client's subscribe/unsubscribe and Service Call Request. No I/O.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace oscar::bridge {

inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";

/// A channel as advertised: a DDS topic (CDR messages, its OMG IDL text as schema), or a side
/// channel the bridge makes from one (JSON messages, a JSON schema; see side_channels.hpp).
struct ChannelInfo {
  std::uint32_t id = 0;
  std::string topic;
  std::string schema_name;  ///< the IDL type, e.g. "oscar::Bool", or e.g. "foxglove.RawImage"
  std::string schema;       ///< self-contained IDL text declaring schema_name, or a JSON schema
  std::string encoding = "cdr";
  std::string schema_encoding = "omgidl";
  std::string source{};  ///< a side channel's DDS topic, the one it is made from; else empty
};

/// A service as advertised (capability "services"): requests and responses are JSON.
struct ServiceInfo {
  std::uint32_t id = 0;
  std::string name;  ///< e.g. "oscar/config"
  std::string type;  ///< e.g. "oscar.Config"
  std::string request_schema_name{};
  std::string request_schema{};  ///< a JSON schema
  std::string response_schema_name{};
  std::string response_schema{};
};

enum class StatusLevel { kInfo = 0, kWarning = 1, kError = 2 };

/// `services`: whether the server offers services (capability "services", JSON encoded calls).
std::string server_info_json(const std::string& name, const std::string& session_id,
                             bool services = false);
std::string advertise_json(const std::vector<ChannelInfo>& channels);
std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids);
std::string status_json(StatusLevel level, const std::string& message);
std::string advertise_services_json(const std::vector<ServiceInfo>& services);
std::string unadvertise_services_json(const std::vector<std::uint32_t>& service_ids);
std::string service_call_failure_json(std::uint32_t service, std::uint32_t call,
                                      const std::string& message);

/// Opcode 0x01, the subscription id (u32 LE) and the receive time (u64 LE, ns); the payload
/// follows in the same frame.
std::array<std::uint8_t, 13> message_data_header(std::uint32_t subscription,
                                                 std::uint64_t receive_ns);

/// A Service Call Request (client binary opcode 0x02).
struct ServiceCall {
  std::uint32_t service = 0;
  std::uint32_t call = 0;
  std::string encoding;
  std::string payload;
};
inline constexpr std::uint8_t kServiceCallRequestOpcode = 0x02;

/// Reads a client's binary Service Call Request: opcode, service id, call id (u32 LE each),
/// the encoding's length (u32 LE), the encoding, the payload.
/// @throws std::invalid_argument naming what is wrong (another opcode, too short, an encoding
///         longer than the frame).
ServiceCall parse_service_call(std::span<const std::uint8_t> frame);

/// A Service Call Response frame (server binary opcode 0x03): the same layout as the request.
std::string service_call_response(std::uint32_t service, std::uint32_t call,
                                  const std::string& encoding, const std::string& payload);

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
