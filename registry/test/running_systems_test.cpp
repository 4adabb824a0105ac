// How boot and the registry tell another system's processes on their domain from their own:
// every participant shows the boot it belongs to ($OSCAR_SYSTEM_INSTANCE) to discovery.
#include "oscar/registry/running_systems.hpp"

#include <stdlib.h>

#include <chrono>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/dds_participant.hpp"
#include "oscar/network.hpp"
#include "oscar/testing/booted_system.hpp"
#include "oscar/testing/eventually.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using ::testing::HasSubstr;
using ::testing::Not;

// A participant made while this process says it belongs to `instance` ("" for none).
std::unique_ptr<DdsParticipant> member(int domain, const std::string& name,
                                       const std::string& instance) {
  if (instance.empty()) {
    unsetenv(kSystemInstanceEnv);
  } else {
    setenv(kSystemInstanceEnv, instance.c_str(), 1);
  }
  return std::make_unique<DdsParticipant>(domain, name);
}

TEST(OtherSystemsOnDomain, AreTheMembersOfAnotherBootOrOfNoneNamedBySystem) {
  oscar::testing::FreeDomain free;
  const int d = free.domain();
  auto busy_module = member(d, "oscar:src", "busy@lab:1234:99");
  auto by_hand = member(d, "oscar:cam", "");
  auto tool = member(d, "oscar-ps", "");  // not a member of any system
  auto ours = member(d, "oscar-monitor:here", "mine@lab:77:5");
  auto our_registry = member(d, "oscar-registry", "mine@lab:77:5");
  std::string seen;
  ASSERT_TRUE(eventually(
      [&] {
        seen = other_systems_on_domain(*our_registry);  // this process says "mine" now
        return seen.find("oscar:src") != std::string::npos &&
               seen.find("oscar:cam") != std::string::npos;
      },
      30s))
      << seen;
  EXPECT_EQ(seen,
            "processes started by hand: oscar:cam; the system 'busy' (boot pid 1234 on lab): "
            "oscar:src");
  EXPECT_THAT(seen, Not(HasSubstr("oscar-monitor:here"))) << "its own system's";
  EXPECT_THAT(seen, Not(HasSubstr("oscar-ps"))) << "a tool belongs to no system";
  // To a process started by hand, the booted systems' processes are others'.
  unsetenv(kSystemInstanceEnv);
  ASSERT_TRUE(eventually(
      [&] { return other_systems_on_domain(*by_hand).find("oscar-registry") != std::string::npos; },
      30s));
  EXPECT_THAT(other_systems_on_domain(*by_hand),
              HasSubstr("the system 'mine' (boot pid 77 on lab): oscar-monitor:here, "
                        "oscar-registry"));
  EXPECT_THAT(other_systems_on_domain(*by_hand), Not(HasSubstr("started by hand")));
}

TEST(OtherSystemsOnDomain, TheRefusalNamesTheDomainAndTheWayOut) {
  EXPECT_EQ(domain_in_use(7, "the system 'busy' (boot pid 1 on lab): oscar:src"),
            "domain 7 is in use by the system 'busy' (boot pid 1 on lab): oscar:src; stop it "
            "(oscar shutdown -d 7) or boot on another domain (--domain N)");
}

}  // namespace
}  // namespace oscar
