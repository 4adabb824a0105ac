// Only the coordinator configures (docs/architecture.md, "Configuration"): the authority comes from
// the process a command is written from, not from the name it claims. A kernel that claims to be
// the coordinator (what the retired sequencer did) is refused; a process hosting no module of the
// system (boot, the registry, an operator's tool) still acts under the name it gives.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/config_client.hpp"

namespace oscar {
namespace {

using test::entry;
using ::testing::HasSubstr;

std::string system_with_an_impostor() {
  return std::string("system: authority\nplugins: ") + OSCAR_TEST_PLUGIN_DIR + R"(
modules:
  - name: cam
    kernels: [ { type: framegrabber, name: cam, params: { source: "synthetic:static" } } ]
    mode: deactivated
  - name: rogue
    kernels:
      - { type: test_impostor, name: rogue, params: { target: cam }, mode: "continuous:300ms" }
)";
}

std::string cam_mode(const SystemState& s) {
  const auto* m = entry(s, "cam");
  const auto* k = m ? test::kernel_state(*m, "cam") : nullptr;
  return k ? k->mode() : "";
}

TEST(Authority, AKernelClaimingTheCoordinatorsNameFromItsModulesProcessIsRefused) {
  test::BootedSystem sys("authority_impostor", system_with_an_impostor());
  sys.running();
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  const std::string refusal =
      "impostor: refused: 'coordinator' may not activate module 'cam': the command comes from "
      "the process of module 'rogue'";
  while (sys.boot_output().find(refusal) == std::string::npos &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_THAT(sys.boot_output(), HasSubstr(refusal));
  EXPECT_THAT(sys.boot_output(), ::testing::Not(HasSubstr("impostor: accepted")));
  EXPECT_EQ(cam_mode(*sys.registry().latest()), "deactivated");
}

TEST(Authority, AProcessHostingNoModuleActsUnderTheNameItGives) {
  test::BootedSystem sys("authority_operator", system_with_an_impostor());
  sys.running();
  ConfigClient operator_tool(sys.participant(), "coordinator");
  const auto reply = operator_tool.send("cam", CMD_ACTIVATE, {"*", "continuous:100ms"});
  ASSERT_TRUE(reply.ok()) << reply.error();
  sys.wait_for([](const SystemState& s) { return cam_mode(s) == "continuous"; });
}

}  // namespace
}  // namespace oscar
