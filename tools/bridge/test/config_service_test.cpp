#include "config_service.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "json_schema_check.hpp"
#include "json_schemas.hpp"

namespace oscar::bridge {
namespace {
using nlohmann::json;

TEST(ConfigService, ReadsACommandInOscarConfigsWords) {
  const auto r =
      parse_config_request(R"({"module":"sources","command":"set-cycle","args":["sig","10ms"]})");
  EXPECT_EQ(r.module, "sources");
  EXPECT_EQ(r.kind, CMD_SET_CYCLE);
  EXPECT_EQ(r.args, (std::vector<std::string>{"sig", "10ms"}));
  EXPECT_EQ(r.text(), "sources set-cycle sig 10ms");
  EXPECT_EQ(parse_config_request(R"({"module":"m","command":"set_param"})").kind, CMD_SET_PARAM);
  EXPECT_EQ(parse_config_request(R"({"module":"m","command":"suspend"})").args.size(), 0u);
}

void expect_refused(const std::string& payload, const std::string& message) {
  try {
    parse_config_request(payload);
    ADD_FAILURE() << "accepted " << payload;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

TEST(ConfigService, RefusesWhatIsNotACommandItOffers) {
  expect_refused("not json", "the request must be a JSON object");
  expect_refused("[1]", "the request must be a JSON object");
  expect_refused(R"({"command":"suspend"})", "'module' must name the target module");
  expect_refused(R"({"module":"","command":"suspend"})", "'module' must name");
  expect_refused(R"({"module":"m"})", "'command' must be one of activate, deactivate");
  expect_refused(R"({"module":"m","command":"shutdown"})",
                 "command 'shutdown' is not offered (offered: activate");
  expect_refused(R"({"module":"m","command":"command","args":["k","x"]})",
                 "command 'command' is not offered");
  expect_refused(R"({"module":"m","command":"rm -rf /"})", "command 'rm -rf /' is not offered");
  expect_refused(R"({"module":"m","command":"trigger","args":"k"})", "'args' must be an array");
  expect_refused(R"({"module":"m","command":"set-cycle","args":["k",10]})",
                 "each of 'args' must be a string");
}

TEST(ConfigService, IsAdvertisedWithJsonSchemasAndAnswersWithTheModulesState) {
  const auto info = config_service_info(3);
  EXPECT_EQ(info.id, 3u);
  EXPECT_EQ(info.name, "oscar/config");
  EXPECT_EQ(json::parse(info.request_schema)["title"], "oscar.ConfigRequest");
  ConfigReply reply;
  reply.module_name("sources");
  reply.ok(true);
  ModuleState state;
  KernelState k;
  k.name("sig");
  k.mode("continuous");
  k.cycle_ns(10'000'000);
  state.kernels({k});
  state.last_transition("sig: continuous(20ms) -> continuous(10ms)");
  reply.state(state);
  const auto r = json::parse(config_response_json(reply));
  EXPECT_EQ(test::schema_mismatch(json::parse(info.response_schema), r), "");
  EXPECT_EQ(r["kernels"][0]["cycle_ms"], 10.0);
  EXPECT_EQ(r["transition"], "sig: continuous(20ms) -> continuous(10ms)");
}

}  // namespace
}  // namespace oscar::bridge
