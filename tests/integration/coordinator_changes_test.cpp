// Services and applets added to and removed from a booted system (docs/coordinator.md, "Adding
// and removing at run time"; seed 000 §4.1.1): `oscar applets add` and `remove`, the
// coordinator's command port, and an applet joining from a process the system file does not
// start, removed when that process is killed.
#include <signal.h>

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "coordinated_system.hpp"
#include "oscar/time.hpp"

namespace oscar {
namespace {

using test::camera_system_with_longer_lease;
using test::CoordinatedSystem;
using test::entry;
using ::testing::HasSubstr;
using Strings = std::vector<std::string>;

// The camera system (module lease 1 s) with a second camera module that no service of the file
// names.
std::string two_camera_system() {
  auto yaml = camera_system_with_longer_lease();
  const std::string modules = "modules:\n";
  yaml.replace(yaml.find(modules), modules.size(),
               modules +
                   "  - name: cam2\n"
                   "    kernels: [ { type: framegrabber, name: cam2, params: { source: "
                   "\"synthetic:static\" } } ]\n"
                   "    mode: deactivated\n");
  const std::string coordinator = "coordinator:\n";
  yaml.replace(yaml.find(coordinator), coordinator.size(), coordinator + "  applet_lease: 1s\n");
  return yaml;
}

bool has_service(const AppletPlan& p, const std::string& name) {
  for (const auto& s : p.services()) {
    if (s.name() == name) return true;
  }
  return false;
}

// `oscar applets ARGS... -d DOMAIN` with its exit code and output.
struct Cli {
  int code = -1;
  std::string output;
};
Cli oscar_applets(const CoordinatedSystem& c, std::vector<std::string> args, const char* log) {
  std::vector<std::string> argv{test::bin("oscar-applets")};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.insert(argv.end(), {"-d", std::to_string(c.sys.domain())});
  const auto out = test::temp_path(log) + ".out";
  Cli result;
  {
    test::Process p(argv, out);
    result.code = p.wait(std::chrono::seconds(30)).value_or(-1);
    result.output = p.output();
  }
  std::error_code ec;
  std::filesystem::remove(out, ec);  // what it printed is in `result`, and in any failure
  return result;
}

// A YAML file of this test's own, removed at the end of the test.
class TempYaml {
 public:
  TempYaml(const char* name, const std::string& text) : path_(test::temp_path(name) + ".yaml") {
    std::ofstream(path_) << text;
  }
  ~TempYaml() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  TempYaml(const TempYaml&) = delete;
  TempYaml& operator=(const TempYaml&) = delete;
  operator const std::string&() const { return path_; }

 private:
  std::string path_;
};

constexpr const char* kCamera2 = R"(services:
  Camera2:
    provided_by: [cam2]
    access: exclusive
    granted: { activate: "continuous:100ms" }
    idle: deactivate
applets:
  - type: event_applet
    name: watcher
    bundles: [ { name: cam2, priority: normal, resources: [ { service: Camera2 } ] } ]
)";

TEST(CoordinatorChanges, AServiceAndAnAppletAddedAtRunTimeActivateTheProviderWhenGranted) {
  CoordinatedSystem c("changes_add", two_camera_system());
  c.sys.running();
  c.wait_plan([](const AppletPlan& p) { return has_service(p, "Camera"); }, "the first plan");
  EXPECT_FALSE(
      has_service(c.wait_plan([](const AppletPlan&) { return true; }, "a plan"), "Camera2"));
  const TempYaml file("changes_add_spec", kCamera2);
  const std::string& spec = file;
  const auto added = oscar_applets(c, {"add", spec}, "changes_add_cli");
  ASSERT_EQ(added.code, 0) << added.output;
  EXPECT_THAT(added.output, HasSubstr(spec + ": added"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return has_service(p, "Camera2") &&
               CoordinatedSystem::applet(p, "watcher") == "coordinator idle";
      },
      "Camera2 and watcher in the plan");
  c.wait_mode("cam2", "deactivated");
  // The added applet runs (event_applet) and the added service configures its module.
  ASSERT_TRUE(c.event("watcher", "cam2", "request").ok());
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera2") == Strings{"watcher"};
      },
      "Camera2 held by watcher");
  c.wait_mode("cam2", "continuous");
  EXPECT_TRUE(c.logged("applet watcher: cam2 granted"));
  // Adding it again is refused: the names are taken.
  const auto again = oscar_applets(c, {"add", spec}, "changes_add_again");
  EXPECT_EQ(again.code, 1) << again.output;
  EXPECT_THAT(again.output, HasSubstr(spec + ":2: duplicate service 'Camera2'"));
  // Removing the applet releases what it held: the service idles, the module is deactivated.
  const auto removed = oscar_applets(c, {"remove", "--applet", "watcher"}, "changes_rm_applet");
  ASSERT_EQ(removed.code, 0) << removed.output;
  EXPECT_THAT(removed.output, HasSubstr("applet watcher: removed applet watcher"));
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::applet(p, "watcher") == "(none)" &&
               CoordinatedSystem::holders(p, "Camera2").empty();
      },
      "watcher gone, Camera2 idle");
  c.wait_mode("cam2", "deactivated");
  const auto gone = oscar_applets(c, {"remove", "--service", "Camera2"}, "changes_rm_service");
  ASSERT_EQ(gone.code, 0) << gone.output;
  c.wait_plan([](const AppletPlan& p) { return !has_service(p, "Camera2"); }, "Camera2 gone");
}

TEST(CoordinatorChanges, RemovingAnAppletThatHoldsAServiceIdlesItAndDeactivatesTheProvider) {
  CoordinatedSystem c("changes_rm_holder");
  c.sys.running();
  ASSERT_TRUE(c.accepted("low", "request"));
  c.wait_plan(
      [](const AppletPlan& p) { return CoordinatedSystem::holders(p, "Camera") == Strings{"low"}; },
      "Camera held by low");
  c.wait_cam_mode("continuous");
  AppletEvent remove;
  remove.event("remove");
  remove.applet("low");
  const auto reply = c.command(remove);
  ASSERT_TRUE(reply.ok()) << reply.error();
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera").empty() &&
               CoordinatedSystem::applet(p, "low") == "(none)" &&
               CoordinatedSystem::applet(p, "high") == "coordinator idle";
      },
      "low gone, Camera idle");
  c.wait_cam_mode("deactivated");
  // Its events are refused now: it is not there.
  const auto late = c.event("low", "request");
  EXPECT_FALSE(late.ok());
  EXPECT_THAT(late.error(), HasSubstr("unknown applet 'low'"));
}

TEST(CoordinatorChanges, RemovingAServiceInUseIsRefusedNamingWhatUsesIt) {
  CoordinatedSystem c("changes_rm_used");
  c.sys.running();
  const auto refused = oscar_applets(c, {"remove", "--service", "Camera"}, "changes_rm_used");
  EXPECT_EQ(refused.code, 1) << refused.output;
  EXPECT_THAT(refused.output,
              HasSubstr("refused: service 'Camera' cannot be removed while the bundles of "
                        "applet(s) 'low', 'high' use it (remove them first)"));
  const auto unknown = oscar_applets(c, {"remove", "--service", "Nowhere"}, "changes_rm_unknown");
  EXPECT_EQ(unknown.code, 1) << unknown.output;
  EXPECT_THAT(unknown.output, HasSubstr("unknown service 'Nowhere'"));
  const auto plan = c.wait_plan([](const AppletPlan& p) { return has_service(p, "Camera"); },
                                "Camera still there");
  EXPECT_TRUE(has_service(plan, "Camera"));
}

TEST(CoordinatorChanges, BadSpecsAreRefusedNamingTheLineAndTheRule) {
  CoordinatedSystem c("changes_bad", two_camera_system());
  c.sys.running();
  auto refused = [&](const char* name, const std::string& text) {
    const TempYaml spec(name, text);
    const auto out = oscar_applets(c, {"add", spec}, name);
    EXPECT_EQ(out.code, 1) << out.output;
    return out.output;
  };
  EXPECT_THAT(refused("changes_bad_module", "services:\n  X:\n    provided_by: [nowhere]\n"),
              HasSubstr(":3: service 'X'.provided_by: no module 'nowhere' in the system"));
  EXPECT_THAT(refused("changes_bad_type",
                      "applets:\n  - type: no_such_type\n    name: x\n    bundles: []\n"),
              HasSubstr(":2: applet 'x': unknown applet type 'no_such_type'"));
  EXPECT_THAT(refused("changes_bad_service",
                      "applets:\n  - type: event_applet\n    name: x\n    bundles:\n      - "
                      "{name: b, resources: [{service: Radar}]}\n"),
              HasSubstr(":5: applet 'x' bundle 'b': unknown service 'Radar'"));
  EXPECT_THAT(refused("changes_bad_yaml", "services: [\n"), HasSubstr("malformed YAML"));
  EXPECT_THAT(refused("changes_bad_process",
                      "applets:\n  - {type: event_applet, name: x, process: elsewhere}\n"),
              HasSubstr(":2: applet 'x': process: and host: belong in the system file"));
  // Nothing of them was added.
  const auto plan =
      c.wait_plan([](const AppletPlan& p) { return has_service(p, "Camera"); }, "the plan");
  EXPECT_FALSE(has_service(plan, "X"));
  EXPECT_EQ(CoordinatedSystem::applet(plan, "x"), "(none)");
}

constexpr const char* kVisitor = R"(applets:
  - type: frame_mode_switcher
    name: visitor
    params: { module: cam, modes: half, switch_every_ms: 200 }
    bundles: [ { name: camera, priority: high, requested: true, resources: [ { service: Camera } ] } ]
)";

// The process "visitors" running the applets of `spec`, which join the system. Named like the
// system's own processes (file and --domain), so that the fixture cleans up after it too; its
// output goes to the system's log folder as `out`.
test::Process visitors(const CoordinatedSystem& c, const std::string& spec,
                       const std::string& out) {
  return test::Process({test::bin("oscar-applet"), c.sys.file(), "--applets", spec, "--module",
                        "visitors", "--domain", std::to_string(c.sys.domain())},
                       c.sys.log_dir() + "/" + out);
}

TEST(CoordinatorChanges, AnAppletJoiningFromAnotherProcessIsAddedAndRemovedWhenItIsKilled) {
  CoordinatedSystem c("changes_join", two_camera_system());
  c.sys.running();
  const TempYaml file("changes_join_spec", kVisitor);
  const std::string& spec = file;
  test::Process visitor = visitors(c, spec, "visitors.out");
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::applet(p, "visitor") == "visitors holding" &&
               CoordinatedSystem::holders(p, "Camera") == Strings{"visitor"};
      },
      "visitor joined from its process and holds Camera");
  c.wait_cam_mode("continuous");
  EXPECT_TRUE(c.logged("coordinator: applet 'visitor' in process 'visitors' joined"));
  c.sys.wait_for([](const SystemState& st) { return st.state() == "running"; });  // notes it
  ASSERT_EQ(kill(visitor.pid(), SIGKILL), 0);
  ASSERT_TRUE(visitor.wait(std::chrono::seconds(10)).has_value());
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::applet(p, "visitor") == "(none)" &&
               CoordinatedSystem::holders(p, "Camera").empty();
      },
      "visitor removed, Camera idle");
  EXPECT_TRUE(c.logged("it joined by its hello, so it is removed"));
  c.wait_cam_mode("deactivated");
  // Its name is free again: a new start of the process joins again.
  test::Process again = visitors(c, spec, "visitors-again.out");
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"visitor"};
      },
      "visitor joined again");
  again.stop();
}

TEST(CoordinatorChanges, ARestartedCoordinatorAddsAJoinedAppletAgainFromItsHello) {
  CoordinatedSystem c("changes_rejoin", two_camera_system());
  c.sys.running();
  const TempYaml file("changes_rejoin_spec", kVisitor);
  const std::string& spec = file;
  test::Process visitor = visitors(c, spec, "visitors.out");
  c.wait_plan(
      [](const AppletPlan& p) {
        return CoordinatedSystem::holders(p, "Camera") == Strings{"visitor"};
      },
      "visitor holds Camera");
  const auto s = c.sys.wait_for([](const SystemState& st) { return entry(st, "coordinator"); });
  const auto first = entry(s, "coordinator")->incarnation();
  const auto killed_at = static_cast<unsigned long long>(wall_now());
  ASSERT_EQ(kill(static_cast<pid_t>(entry(s, "coordinator")->pid()), SIGKILL), 0);
  c.sys.wait_for([&](const SystemState& st) {
    const auto* m = entry(st, "coordinator");
    return m && m->incarnation() > first && m->status() == "running";
  });
  c.wait_plan(
      [&](const AppletPlan& p) {
        return p.stamp_ns() > killed_at &&
               CoordinatedSystem::applet(p, "visitor") == "visitors holding" &&
               CoordinatedSystem::holders(p, "Camera") == Strings{"visitor"};
      },
      "the restarted coordinator added visitor again from its hello");
  visitor.stop();
}

}  // namespace
}  // namespace oscar
