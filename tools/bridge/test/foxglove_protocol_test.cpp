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

TEST(FoxgloveProtocol, OffersServicesOnlyWhenAskedTo) {
  const auto without = json::parse(server_info_json("oscar bridge", "1"));
  EXPECT_EQ(without["capabilities"], json::array());
  const auto with = json::parse(server_info_json("oscar bridge", "1", true));
  EXPECT_EQ(with["capabilities"], json::array({"services"}));
  EXPECT_EQ(with["supportedEncodings"], json::array({"json"}));
  const auto a = json::parse(advertise_services_json({{.id = 1,
                                                       .name = "oscar/config",
                                                       .type = "oscar.Config",
                                                       .request_schema_name = "Req",
                                                       .request_schema = "{}",
                                                       .response_schema_name = "Res",
                                                       .response_schema = "{}"}}));
  EXPECT_EQ(a["op"], "advertiseServices");
  const auto& s = a["services"][0];
  EXPECT_EQ(s["id"], 1);
  EXPECT_EQ(s["name"], "oscar/config");
  EXPECT_EQ(s["request"]["encoding"], "json");
  EXPECT_EQ(s["request"]["schemaEncoding"], "jsonschema");
  EXPECT_EQ(s["request"]["schemaName"], "Req");
  EXPECT_EQ(s["responseSchema"], "{}");
  EXPECT_EQ(json::parse(service_call_failure_json(1, 9, "no")),
            json::parse(R"({"op":"serviceCallFailure","serviceId":1,"callId":9,"message":"no"})"));
}

std::vector<std::uint8_t> frame_of(const std::string& s) { return {s.begin(), s.end()}; }

TEST(FoxgloveProtocol, ReadsAServiceCallAndWritesItsResponseInTheSameLayout) {
  // A response frame has the request's layout with opcode 3: reuse it to build a request.
  auto bytes = frame_of(service_call_response(0x01020304, 7, "json", R"({"a":1})"));
  EXPECT_EQ(bytes[0], 3);
  EXPECT_EQ(bytes[1], 4);
  EXPECT_EQ(bytes[9], 4);  // the encoding's length
  bytes[0] = 2;
  const auto call = parse_service_call(bytes);
  EXPECT_EQ(call.service, 0x01020304u);
  EXPECT_EQ(call.call, 7u);
  EXPECT_EQ(call.encoding, "json");
  EXPECT_EQ(call.payload, R"({"a":1})");
}

void expect_call_rejected(std::vector<std::uint8_t> frame, const std::string& message) {
  try {
    parse_service_call(frame);
    ADD_FAILURE() << "accepted " << frame.size() << " bytes";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(e.what(), message);
  }
}

TEST(FoxgloveProtocol, RejectsMalformedServiceCallsSayingWhy) {
  expect_call_rejected({}, "an empty binary message");
  expect_call_rejected({1, 0, 0, 0, 0},
                       "binary opcode 1 is not offered by this server (only 2, a service call "
                       "request)");
  expect_call_rejected({2, 1, 0, 0},
                       "service call request: 4 bytes, shorter than its 13-byte header");
  expect_call_rejected({2, 1, 0, 0, 0, 1, 0, 0, 0, 0xff, 0xff, 0xff, 0xff, 'j'},
                       "service call request: its encoding's length (4294967295) runs past the "
                       "frame");
}

}  // namespace
}  // namespace oscar::bridge
