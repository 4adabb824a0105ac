// Modules that are plain clients of a discovery server (docs/network.md, "Discovery: static
// peers or a discovery server"), in this test process.
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>

#include "oscar/discovery_server.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/module.hpp"
#include "oscar/testing/booted_system.hpp"
#include "oscar/testing/eventually.hpp"
#include "test_kernels.hpp"

namespace oscar {
namespace {

constexpr char kNoIntraprocessDelivery[] = R"(<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <library_settings><intraprocess_delivery>OFF</intraprocess_delivery></library_settings>
</dds>)";

test::Collect& collect(Module& m, const std::string& name) {
  return dynamic_cast<test::Collect&>(m.kernel(name).kernel());
}

// Modules under a discovery server are its plain clients (docs/network.md): a module's
// participant learns of a producer's writer only once it reads the producer's topic, and its
// input still reads each producer as the producer's writer offers, so that a transient-local
// producer's history arrives and a best-effort one is read best effort.
// The four modules share this process, which no booted module does (one module per oscar-run).
// Fast DDS 2.9 delivering within a process to a plain client's reader crashed in
// StatelessWriter::intraprocess_delivery in 4 of 8 runs under ASan (0 of 8 with it off), so this
// test has Fast DDS deliver through its transports, as between the processes of a system.
TEST(DiscoveryServerPlainClients, AnInputReadsEachProducerAsItsWriterOffers) {
  ASSERT_EQ(
      eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->load_XML_profiles_string(
          kNoIntraprocessDelivery, sizeof kNoIntraprocessDelivery - 1),
      eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK);
  // Two free domains, the lower one used: a discovery server's port (id 119) does not fit in
  // domain 232's, the first FreeDomain tries.
  oscar::testing::FreeDomain higher, free;
  DiscoveryServer server(free.domain(), NetworkConfig::from_yaml(YAML::Load("{discovery: server}")),
                         0);
  const auto start = [&](const std::string& yaml) {
    auto m = std::make_unique<Module>(
        ModuleSpec::from_yaml(YAML::Load("network: { discovery: server }\n" + yaml), "test"),
        plugin_search_path());
    m->start(free.domain());
    return m;
  };
  auto history = start(R"(
name: history
mode: { continuous: 2ms }
kernels: [ { type: test_emitter, name: tl, params: { transient_local: true, depth: 4, count: 10 } } ]
)");
  auto& out = *history->kernel("tl").ports().outputs.front();
  ASSERT_TRUE(eventually([&] { return out.published() == 10; }));
  auto best_effort = start(R"(
name: best_effort
mode: { continuous: 5ms }
kernels: [ { type: test_emitter, name: be, params: { reliable: false } } ]
)");
  auto reliable = start(R"(
name: reliable
mode: { continuous: 5ms }
kernels: [ { type: test_emitter, name: rel } ]
)");
  auto sink = start(R"(
name: sink
mode: { continuous: 5ms }
kernels:
  - { type: test_collect, name: from_tl, inputs: { in: tl/out } }
  - { type: test_collect, name: from_be, inputs: { in: be/out } }
  - { type: test_collect, name: from_rel, inputs: { in: rel/out } }
)");
  EXPECT_TRUE(eventually([&] { return collect(*sink, "from_be").seen().size() >= 5; }));
  EXPECT_TRUE(eventually([&] { return collect(*sink, "from_rel").seen().size() >= 5; }));
  EXPECT_TRUE(eventually([&] { return collect(*sink, "from_tl").seen().size() == 4; }))
      << "the history (depth 4) of a producer that had stopped before the input connected";
  const auto tl = collect(*sink, "from_tl").seen();
  ASSERT_FALSE(tl.empty());
  EXPECT_EQ(tl.back()->header().seq(), 10u);
}

}  // namespace
}  // namespace oscar
