#include "foxglove_protocol.hpp"

#include <stdexcept>

#include <nlohmann/json.hpp>

namespace oscar::bridge {
using nlohmann::json;

std::string server_info_json(const std::string& name, const std::string& session_id,
                             bool services) {
  return json{{"op", "serverInfo"},
              {"name", name},
              {"capabilities", services ? json::array({"services"}) : json::array()},
              {"supportedEncodings", services ? json::array({"json"}) : json::array()},
              {"metadata", json::object()},
              {"sessionId", session_id}}
      .dump();
}

std::string advertise_json(const std::vector<ChannelInfo>& channels) {
  json list = json::array();
  for (const auto& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids) {
  return json{{"op", "unadvertise"}, {"channelIds", channel_ids}}.dump();
}

std::string status_json(StatusLevel level, const std::string& message) {
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}.dump();
}

std::string advertise_services_json(const std::vector<ServiceInfo>& services) {
  json list = json::array();
  for (const auto& s : services) {
    const auto definition = [](const std::string& name, const std::string& schema) {
      return json{{"encoding", "json"},
                  {"schemaName", name},
                  {"schemaEncoding", "jsonschema"},
                  {"schema", schema}};
    };
    // `request`/`response` are the spec's; `requestSchema`/`responseSchema` what clients
    // before them read (deprecated, still required by those).
    list.push_back({{"id", s.id},
                    {"name", s.name},
                    {"type", s.type},
                    {"request", definition(s.request_schema_name, s.request_schema)},
                    {"response", definition(s.response_schema_name, s.response_schema)},
                    {"requestSchema", s.request_schema},
                    {"responseSchema", s.response_schema}});
  }
  return json{{"op", "advertiseServices"}, {"services", list}}.dump();
}

std::string unadvertise_services_json(const std::vector<std::uint32_t>& service_ids) {
  return json{{"op", "unadvertiseServices"}, {"serviceIds", service_ids}}.dump();
}

std::string service_call_failure_json(std::uint32_t service, std::uint32_t call,
                                      const std::string& message) {
  return json{
      {"op", "serviceCallFailure"}, {"serviceId", service}, {"callId", call}, {"message", message}}
      .dump();
}

namespace {
std::uint32_t u32_at(std::span<const std::uint8_t> bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(bytes[at + i]) << (8 * i);
  return v;
}
void append_u32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}
}  // namespace

ServiceCall parse_service_call(std::span<const std::uint8_t> frame) {
  constexpr std::size_t kHeader = 13;  // opcode, service id, call id, encoding length
  if (frame.empty() || frame[0] != kServiceCallRequestOpcode) {
    throw std::invalid_argument(
        frame.empty() ? "an empty binary message"
                      : "binary opcode " + std::to_string(frame[0]) +
                            " is not offered by this server (only 2, a service call request)");
  }
  if (frame.size() < kHeader) {
    throw std::invalid_argument("service call request: " + std::to_string(frame.size()) +
                                " bytes, shorter than its 13-byte header");
  }
  ServiceCall call;
  call.service = u32_at(frame, 1);
  call.call = u32_at(frame, 5);
  const std::size_t encoding_length = u32_at(frame, 9);
  if (encoding_length > frame.size() - kHeader) {
    throw std::invalid_argument("service call request: its encoding's length (" +
                                std::to_string(encoding_length) + ") runs past the frame");
  }
  const auto* bytes = reinterpret_cast<const char*>(frame.data());
  call.encoding.assign(bytes + kHeader, encoding_length);
  call.payload.assign(bytes + kHeader + encoding_length, frame.size() - kHeader - encoding_length);
  return call;
}

std::string service_call_response(std::uint32_t service, std::uint32_t call,
                                  const std::string& encoding, const std::string& payload) {
  std::string out;
  out.reserve(13 + encoding.size() + payload.size());
  out += static_cast<char>(0x03);
  append_u32(out, service);
  append_u32(out, call);
  append_u32(out, static_cast<std::uint32_t>(encoding.size()));
  return out + encoding + payload;
}

std::array<std::uint8_t, 13> message_data_header(std::uint32_t subscription,
                                                 std::uint64_t receive_ns) {
  std::array<std::uint8_t, 13> h{};
  h[0] = 0x01;
  for (int i = 0; i < 4; ++i) h[1 + i] = static_cast<std::uint8_t>(subscription >> (8 * i));
  for (int i = 0; i < 8; ++i) h[5 + i] = static_cast<std::uint8_t>(receive_ns >> (8 * i));
  return h;
}

namespace {
std::uint32_t id_field(const json& object, const char* key, const char* op) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_number_unsigned() || it->get<std::uint64_t>() > UINT32_MAX) {
    throw std::invalid_argument(std::string(op) + ": '" + key +
                                "' must be a number from 0 to 4294967295");
  }
  return it->get<std::uint32_t>();
}

const json& array_field(const json& object, const char* key, const char* op) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_array()) {
    throw std::invalid_argument(std::string(op) + ": '" + key + "' must be an array");
  }
  return *it;
}
}  // namespace

ClientRequest parse_client_message(std::string_view text) {
  const auto message = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded() || !message.is_object()) {
    throw std::invalid_argument("a text message must be a JSON object");
  }
  const auto op = message.find("op");
  if (op == message.end() || !op->is_string()) {
    throw std::invalid_argument("a text message needs a string field 'op'");
  }
  const auto name = op->get<std::string>();
  if (name == "subscribe") {
    Subscribe s;
    for (const auto& item : array_field(message, "subscriptions", "subscribe")) {
      if (!item.is_object())
        throw std::invalid_argument("subscribe: each subscription is an object");
      s.subscriptions.emplace_back(id_field(item, "id", "subscribe"),
                                   id_field(item, "channelId", "subscribe"));
    }
    return s;
  }
  if (name == "unsubscribe") {
    Unsubscribe u;
    for (const auto& id : array_field(message, "subscriptionIds", "unsubscribe")) {
      if (!id.is_number_unsigned() || id.get<std::uint64_t>() > UINT32_MAX) {
        throw std::invalid_argument("unsubscribe: 'subscriptionIds' must hold numbers");
      }
      u.subscription_ids.push_back(id.get<std::uint32_t>());
    }
    return u;
  }
  return Unsupported{name};
}

}  // namespace oscar::bridge
