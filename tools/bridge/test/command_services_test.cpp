#include "command_services.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "json_schema_check.hpp"
#include "json_schemas.hpp"
#include "oscar/command_types.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/swarm_types.hpp"

namespace oscar::bridge {
namespace {
using nlohmann::json;

// Every IDL type OSCAR embeds, as the bridge reads them.
const inspect::IdlTypes& oscar_types() {
  static const auto types = [] {
    inspect::IdlTypes t;
    for (const auto& [name, text] : idl_texts()) t.add(text);
    return t;
  }();
  return types;
}

ModuleEntry module(
    const std::string& name, const std::string& status,
    const std::vector<std::pair<std::string, std::vector<DeclaredCommand>>>& kernels) {
  ModuleEntry m;
  m.name(name);
  m.status(status);
  ModuleState state;
  state.module_name(name);
  for (const auto& [kernel, commands] : kernels) {
    KernelState k;
    k.name(kernel);
    k.commands(commands);
    state.kernels().push_back(k);
  }
  m.state(state);
  return m;
}

DeclaredCommand declared(const std::string& name, const std::string& type) {
  DeclaredCommand c;
  c.name(name);
  c.type(type);
  return c;
}

SystemState robots_and_cams(const std::string& robots_status) {
  SystemState s;
  s.modules().push_back(module("robots", robots_status,
                               {{"r1",
                                 {declared("propose", "oscar::Trajectory"),
                                  declared("commit", "oscar::TransactionDecision")}},
                                {"r2", {}}}));
  s.modules().push_back(
      module("cams", "running", {{"cam_a", {declared("frame_mode", "oscar::SetFrameMode")}}}));
  return s;
}

TEST(CommandServices, OffersTheCommandPortsOfRunningModulesOnly) {
  const auto running = running_commands(robots_and_cams("running"));
  ASSERT_EQ(running.size(), 3u);
  EXPECT_EQ(running[0].service_name(), "oscar/robots/r1/propose");
  EXPECT_EQ(running[0].request_type, "oscar::Trajectory");
  EXPECT_EQ(running[2].service_name(), "oscar/cams/cam_a/frame_mode");
  for (const auto* status : {"starting", "failed", "restarting", "stopped", "standby"}) {
    const auto only_cams = running_commands(robots_and_cams(status));
    ASSERT_EQ(only_cams.size(), 1u) << status;
    EXPECT_EQ(only_cams[0].module, "cams") << status;
  }
}

TEST(CommandServices, FollowsModulesThatGoAndComeBackUnderTheSameIds) {
  CommandServices services(oscar_types(), 2);
  const auto first = services.update(running_commands(robots_and_cams("running")));
  ASSERT_EQ(first.added.size(), 3u);
  EXPECT_TRUE(first.removed.empty());
  EXPECT_EQ(first.added[0].id, 2u);
  EXPECT_EQ(first.added[0].name, "oscar/robots/r1/propose");
  EXPECT_EQ(first.added[2].id, 4u);
  EXPECT_EQ(services.services().size(), 3u);
  EXPECT_TRUE(services.update(running_commands(robots_and_cams("running"))).added.empty());

  const auto gone = services.update(running_commands(robots_and_cams("restarting")));
  EXPECT_TRUE(gone.added.empty());
  EXPECT_EQ(gone.removed, (std::vector<std::uint32_t>{2, 3}));
  EXPECT_EQ(services.offered(2), nullptr);
  ASSERT_NE(services.ever(2), nullptr);
  EXPECT_EQ(services.ever(2)->module, "robots");
  EXPECT_NE(services.offered(4), nullptr);

  const auto back = services.update(running_commands(robots_and_cams("running")));
  ASSERT_EQ(back.added.size(), 2u);
  EXPECT_EQ(back.added[0].id, 2u);
  EXPECT_EQ(back.added[1].id, 3u);
  EXPECT_EQ(services.services().size(), 3u);
}

TEST(CommandServices, SaysOnceThatARequestTypeWithoutIdlIsNotOffered) {
  CommandServices services(oscar_types(), 2);
  SystemState s;
  s.modules().push_back(
      module("arm", "running", {{"arm", {declared("hold", "acme::HoldRequest")}}}));
  const auto first = services.update(running_commands(s));
  EXPECT_TRUE(first.added.empty());
  ASSERT_EQ(first.unknown_types.size(), 1u);
  EXPECT_EQ(first.unknown_types[0].service_name(), "oscar/arm/arm/hold");
  EXPECT_TRUE(services.update(running_commands(s)).unknown_types.empty());
}

TEST(CommandServices, DescribesTheRequestAsAJsonSchemaOfItsIdlMembers) {
  const auto schema = json::parse(request_json_schema(oscar_types(), "oscar::Trajectory"));
  EXPECT_EQ(schema["title"], "oscar::Trajectory");
  EXPECT_EQ(schema["type"], "object");
  const auto& p = schema["properties"];
  EXPECT_EQ(p["robot"]["type"], "string");
  EXPECT_EQ(p["transaction"]["type"], json::array({"integer", "string"}));
  const auto& section = p["sections"]["items"];
  EXPECT_EQ(p["sections"]["type"], "array");
  EXPECT_EQ(section["properties"]["open_end"]["type"], "boolean");
  EXPECT_EQ(section["properties"]["waypoints"]["items"]["properties"]["x"]["type"], "number");
  // An enum is its enumerators' names.
  const auto request = json::parse(request_json_schema(oscar_types(), "oscar::SwarmRequest"));
  EXPECT_EQ(request["properties"]["kind"]["type"], "string");
  EXPECT_EQ(request["properties"]["kind"]["enum"][0], "SWARM_SCHEDULE");
  try {
    request_json_schema(oscar_types(), "acme::Nothing");
    ADD_FAILURE() << "a schema of an unknown type";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "no IDL text here declares the struct 'acme::Nothing'");
  }
}

TEST(CommandServices, EncodesAJsonRequestAsTheCompiledTypeDoes) {
  TransactionDecision d;
  d.robot("r1");
  d.transaction(1795715823215514942ull);  // more than a JavaScript number holds exactly
  const auto expected = idl_type_info<TransactionDecision>().serialize(&d);
  EXPECT_EQ(request_cdr(oscar_types(), "oscar::TransactionDecision",
                        R"({"robot": "r1", "transaction": "1795715823215514942"})"),
            expected);
  EXPECT_EQ(request_cdr(oscar_types(), "oscar::TransactionDecision",
                        R"({"robot": "r1", "transaction": 1795715823215514942})"),
            expected);

  Trajectory t;
  t.robot("r7");
  t.transaction(7);
  TrajectorySection s;
  s.from_ns(100);
  s.open_end(true);
  SwarmWaypoint a, b;
  a.x(3);
  a.y(4);
  a.t_ns(100);
  b.x(3.5);
  b.y(4);
  b.t_ns(200);
  s.waypoints({a, b});
  t.sections({s});
  EXPECT_EQ(request_cdr(oscar_types(), "oscar::Trajectory", R"({"robot": "r7", "transaction": 7,
      "sections": [{"from_ns": 100, "open_end": true,
                    "waypoints": [{"x": 3, "y": 4, "t_ns": 100}, {"x": 3.5, "y": 4, "t_ns": 200}]}]})"),
            idl_type_info<Trajectory>().serialize(&t));

  SetFrameMode defaults;  // every member left out
  EXPECT_EQ(request_cdr(oscar_types(), "oscar::SetFrameMode", "{}"),
            idl_type_info<SetFrameMode>().serialize(&defaults));
}

void expect_wrong(const std::string& type, const std::string& payload, const std::string& message) {
  try {
    request_cdr(oscar_types(), type, payload);
    ADD_FAILURE() << "encoded " << payload;
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

TEST(CommandServices, RefusesARequestThatIsNoneOfItsType) {
  expect_wrong("oscar::TransactionDecision", "not json",
               "the request must be a JSON object of the members of oscar::TransactionDecision");
  expect_wrong("oscar::TransactionDecision", "[1]",
               "the request must be a JSON object of the members of oscar::TransactionDecision");
  expect_wrong("oscar::TransactionDecision", R"({"robot": "r1", "transaction": "seven"})",
               "transaction: 'seven' is no unsigned long long");
  expect_wrong("oscar::TransactionDecision", R"({"robot": "r1", "transaction": -1})",
               "transaction: '-1' is no unsigned long long");
  expect_wrong("oscar::TransactionDecision", R"({"robot": 1})", "robot: 1 is no string");
  expect_wrong("oscar::TransactionDecision", R"({"robot": "r1", "tx": 7})",
               "oscar::TransactionDecision has no member 'tx' (members: robot, transaction)");
  expect_wrong("oscar::Trajectory", R"({"sections": [{"open_end": "yes"}]})",
               "sections[0].open_end: \"yes\" is no boolean");
  expect_wrong("oscar::Trajectory", R"({"sections": {"from_ns": 1}})",
               "sections: {\"from_ns\":1} is no array");
  expect_wrong("oscar::SwarmRequest", R"({"kind": "SWARM_EXPLODE"})",
               "kind: 'SWARM_EXPLODE' is no enumerator of oscar::SwarmRequestKind "
               "(SWARM_SCHEDULE, SWARM_PERIODIC, SWARM_DEPENDENT, SWARM_UNSCHEDULE, "
               "SWARM_RESCHEDULE, SWARM_UNSCHEDULE_SET, SWARM_ADD_OBSTACLES, "
               "SWARM_REMOVE_OBSTACLES)");
}

TEST(CommandServices, AnswersWithTheKernelsWordsInItsResponseSchema) {
  const KernelCommand c{"cams", "cam_a", "frame_mode", "oscar::SetFrameMode"};
  const auto response = json::parse(command_response_json(c, "frame mode full -> half"));
  EXPECT_EQ(response, json::parse(R"({"module": "cams", "kernel": "cam_a",
      "command": "frame_mode", "answer": "frame mode full -> half"})"));
  EXPECT_EQ(test::schema_mismatch(json::parse(json_schema("oscar.CommandResponse")), response), "");
  CommandServices services(oscar_types(), 2);
  SystemState s;
  s.modules().push_back(
      module("cams", "running", {{"cam_a", {declared("frame_mode", "oscar::SetFrameMode")}}}));
  const auto added = services.update(running_commands(s)).added;
  ASSERT_EQ(added.size(), 1u);
  EXPECT_EQ(added[0].type, "oscar::SetFrameMode");
  EXPECT_EQ(added[0].request_schema_name, "oscar::SetFrameMode");
  EXPECT_EQ(json::parse(added[0].request_schema)["properties"]["mode"]["type"], "string");
  EXPECT_EQ(added[0].response_schema_name, "oscar.CommandResponse");
}

}  // namespace
}  // namespace oscar::bridge
