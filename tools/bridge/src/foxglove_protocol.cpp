#include "foxglove_protocol.hpp"

#include <stdexcept>

#include <nlohmann/json.hpp>

namespace oscar::bridge {
using nlohmann::json;

std::string server_info_json(const std::string& name, const std::string& session_id) {
  return json{{"op", "serverInfo"},
              {"name", name},
              {"capabilities", json::array()},
              {"supportedEncodings", json::array()},
              {"metadata", json::object()},
              {"sessionId", session_id}}
      .dump();
}

std::string advertise_json(const std::vector<ChannelInfo>& channels) {
  json list = json::array();
  for (const auto& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", "cdr"},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", "omgidl"}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertise_json(const std::vector<std::uint32_t>& channel_ids) {
  return json{{"op", "unadvertise"}, {"channelIds", channel_ids}}.dump();
}

std::string status_json(StatusLevel level, const std::string& message) {
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}.dump();
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
