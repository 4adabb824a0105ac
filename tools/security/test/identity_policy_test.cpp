#include "identity_policy.hpp"

#include <fnmatch.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar::security {
namespace {

constexpr const char* kSystem = R"(
system: t
hosts: { a: { local: true }, b: { netns: hb } }
modules:
  - { name: camera, host: a, kernels: [ { type: bench_source, name: cam } ] }
  - name: viewer
    host: b
    kernels: [ { type: bench_sink, name: view, inputs: { in: cam/out } } ]
coordinator:
  host: a
  applets:
    - { type: event_applet, name: Remote, process: helpers }
)";

std::vector<IdentityPolicy> identities() {
  return identities_of(SystemSpec::parse(YAML::Load(kSystem), "t.yaml"));
}

const IdentityPolicy& find(const std::vector<IdentityPolicy>& all, const std::string& name) {
  for (const auto& i : all) {
    if (i.name == name) return i;
  }
  throw std::invalid_argument("no identity " + name);
}

// As Fast DDS's Access-Permissions plugin matches a topic against a <publish> list.
bool may_publish(const IdentityPolicy& identity, const std::string& topic) {
  for (const auto& pattern : identity.publish) {
    if (fnmatch(pattern.c_str(), topic.c_str(), FNM_NOESCAPE) == 0) return true;
  }
  return false;
}

std::vector<std::string> writers_of(const std::vector<IdentityPolicy>& all,
                                    const std::string& topic) {
  std::vector<std::string> names;
  for (const auto& i : all) {
    if (may_publish(i, topic)) names.push_back(i.name);
  }
  return names;
}

TEST(IdentityPolicy, EveryProcessOfTheSystemHasAnIdentity) {
  std::vector<std::string> names;
  for (const auto& i : identities()) names.push_back(i.name);
  EXPECT_THAT(names, ::testing::ElementsAre(
                         "registry", "boot", "operator", "operator_boot", "monitor.a", "monitor.b",
                         "module.camera", "module.viewer", "module.coordinator", "module.helpers"));
}

TEST(IdentityPolicy, AModuleWritesOnlyItsOwnCuesStateAndReplies) {
  const auto all = identities();
  const auto& viewer = find(all, "module.viewer");
  EXPECT_TRUE(may_publish(viewer, "oscar/cue/view/out"));
  EXPECT_TRUE(may_publish(viewer, "oscar/pull/view/out/reply"));
  EXPECT_TRUE(may_publish(viewer, "oscar/pull/cam/out/request")) << "it pulls what it is wired to";
  EXPECT_TRUE(may_publish(viewer, "oscar/config_reply/viewer"));
  EXPECT_TRUE(may_publish(viewer, "oscar/registry/module_state"));
  EXPECT_TRUE(may_publish(viewer, "oscar/registry/alive"));
  EXPECT_FALSE(may_publish(viewer, "oscar/cue/cam/out")) << "another module's cue";
  EXPECT_FALSE(may_publish(viewer, "oscar/pull/cam/out/reply"));
  EXPECT_FALSE(may_publish(viewer, "oscar/config_reply/camera"));
  EXPECT_FALSE(may_publish(viewer, "oscar/config/viewer")) << "not even its own configuration";
  EXPECT_FALSE(may_publish(viewer, "oscar/registry/launch"));
}

TEST(IdentityPolicy, OnlyCoordinatorRegistryAndBootConfigureAndOnlyTheRegistryLaunches) {
  const auto all = identities();
  EXPECT_THAT(writers_of(all, "oscar/config/camera"),
              ::testing::ElementsAre("registry", "boot", "operator_boot", "module.coordinator"));
  EXPECT_THAT(writers_of(all, "oscar/registry/launch"), ::testing::ElementsAre("registry"));
  EXPECT_THAT(writers_of(all, "oscar/system/state"), ::testing::ElementsAre("registry"));
  EXPECT_THAT(writers_of(all, "oscar/registry/process"),
              ::testing::ElementsAre("monitor.a", "monitor.b"));
  EXPECT_THAT(writers_of(all, "oscar/registry/children"),
              ::testing::ElementsAre("monitor.a", "monitor.b"));
  EXPECT_THAT(writers_of(all, "oscar/coordinator/plan"),
              ::testing::ElementsAre("module.coordinator"));
  // Clock probes and estimates come from the monitors, echoes from the registry only.
  EXPECT_THAT(writers_of(all, "oscar/registry/clock/probe"),
              ::testing::ElementsAre("monitor.a", "monitor.b"));
  EXPECT_THAT(writers_of(all, "oscar/registry/clocks"),
              ::testing::ElementsAre("monitor.a", "monitor.b"));
  EXPECT_THAT(writers_of(all, "oscar/registry/clock/echo"), ::testing::ElementsAre("registry"));
  EXPECT_THAT(writers_of(all, "oscar/sched/hello"), ::testing::ElementsAre("module.helpers"));
  // Jobs and world changes for the swarm: the coordinator's and other applets, and the operator
  // acting with boot's authority (`oscar swarm submit`); not boot itself.
  EXPECT_THAT(writers_of(all, "oscar/swarm/request"),
              ::testing::ElementsAre("operator_boot", "module.coordinator", "module.helpers"));
}

TEST(IdentityPolicy, TheOperatorOnlyReads) {
  const auto all = identities();
  const auto& op = find(all, "operator");
  EXPECT_TRUE(op.publish.empty());
  EXPECT_THAT(op.subscribe, ::testing::ElementsAre("*"));
}

}  // namespace
}  // namespace oscar::security
