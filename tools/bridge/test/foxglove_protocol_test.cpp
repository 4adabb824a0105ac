#include "foxglove_protocol.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace oscar::bridge {
namespace {
using nlohmann::json;

TEST(FoxgloveProtocol, AdvertisesCdrChannelsWithOmgIdlSchemas) {
  const auto text = advertise_json({{7, "oscar/cue/sig/out", "oscar::Bool", "module oscar {};"}});
  const auto a = json::parse(text);
  EXPECT_EQ(a["op"], "advertise");
  ASSERT_EQ(a["channels"].size(), 1u);
  const auto& c = a["channels"][0];
  EXPECT_EQ(c["id"], 7);
  EXPECT_EQ(c["topic"], "oscar/cue/sig/out");
  EXPECT_EQ(c["encoding"], "cdr");
  EXPECT_EQ(c["schemaName"], "oscar::Bool");
  EXPECT_EQ(c["schemaEncoding"], "omgidl");
  EXPECT_EQ(c["schema"], "module oscar {};");
}

TEST(FoxgloveProtocol, ServerInfoUnadvertiseAndStatusHaveTheirFields) {
  const auto info = json::parse(server_info_json("oscar bridge", "123"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["name"], "oscar bridge");
  EXPECT_TRUE(info["capabilities"].is_array());
  EXPECT_EQ(info["sessionId"], "123");
  EXPECT_EQ(json::parse(unadvertise_json({1, 2})),
            json::parse(R"({"op":"unadvertise","channelIds":[1,2]})"));
  EXPECT_EQ(json::parse(status_json(StatusLevel::kWarning, "slow")),
            json::parse(R"({"op":"status","level":1,"message":"slow"})"));
}

TEST(FoxgloveProtocol, MessageDataHeaderIsOpcodeThenLittleEndianIdAndTime) {
  const auto h = message_data_header(0x04030201u, 0x0c0b0a0908070605ull);
  const std::array<std::uint8_t, 13> expected{1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  EXPECT_EQ(h, expected);
}

TEST(FoxgloveProtocol, ReadsSubscribeAndUnsubscribe) {
  const auto s = parse_client_message(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":5}]})");
  ASSERT_TRUE(std::holds_alternative<Subscribe>(s));
  const auto& subs = std::get<Subscribe>(s).subscriptions;
  ASSERT_EQ(subs.size(), 2u);
  EXPECT_EQ(subs[1], (std::pair<std::uint32_t, std::uint32_t>{1, 5}));
  const auto u = parse_client_message(R"({"op":"unsubscribe","subscriptionIds":[0,1]})");
  ASSERT_TRUE(std::holds_alternative<Unsubscribe>(u));
  EXPECT_EQ(std::get<Unsubscribe>(u).subscription_ids, (std::vector<std::uint32_t>{0, 1}));
  const auto other = parse_client_message(R"({"op":"getParameters","parameterNames":[]})");
  ASSERT_TRUE(std::holds_alternative<Unsupported>(other));
  EXPECT_EQ(std::get<Unsupported>(other).op, "getParameters");
}

void expect_rejected(const std::string& text, const std::string& message) {
  try {
    parse_client_message(text);
    ADD_FAILURE() << "accepted " << text;
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(e.what(), message) << text;
  }
}

TEST(FoxgloveProtocol, RejectsMalformedClientMessagesSayingWhy) {
  expect_rejected("not json", "a text message must be a JSON object");
  expect_rejected("[1]", "a text message must be a JSON object");
  expect_rejected(R"({"subscriptions":[]})", "a text message needs a string field 'op'");
  expect_rejected(R"({"op":"subscribe"})", "subscribe: 'subscriptions' must be an array");
  expect_rejected(R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})",
                  "subscribe: 'id' must be a number from 0 to 4294967295");
  expect_rejected(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":4294967296}]})",
                  "subscribe: 'channelId' must be a number from 0 to 4294967295");
  expect_rejected(R"({"op":"unsubscribe","subscriptionIds":["a"]})",
                  "unsubscribe: 'subscriptionIds' must hold numbers");
}

}  // namespace
}  // namespace oscar::bridge
