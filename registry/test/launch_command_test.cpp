#include "oscar/registry/launch_command.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar {
namespace {

using Argv = std::vector<std::string>;
using ::testing::HasSubstr;

TEST(LaunchCommand, LocalHostsRunTheCommandAsItIs) {
  HostSpec h;
  EXPECT_EQ(on_host(h, {"oscar-monitor", "--host", "a"}), (Argv{"oscar-monitor", "--host", "a"}));
}

TEST(LaunchCommand, NetnsHostsRunItInTheirNamespace) {
  HostSpec h;
  h.kind = HostSpec::Kind::kNetns;
  h.netns = "scooter";
  EXPECT_EQ(on_host(h, {"oscar-monitor", "--host", "scooter"}),
            (Argv{"ip", "netns", "exec", "scooter", "oscar-monitor", "--host", "scooter"}));
}

TEST(LaunchCommand, SshHostsGetOneQuotedRemoteCommand) {
  HostSpec h;
  h.kind = HostSpec::Kind::kSsh;
  h.ssh = "robot@marvin";
  h.ssh_options = {"Port=2222", "IdentityFile=/keys/robot"};
  EXPECT_EQ(on_host(h, {"/opt/oscar/bin/oscar-monitor", "--system", "my system.yaml", "it's"}),
            (Argv{"ssh", "-o", "BatchMode=yes", "-o", "Port=2222", "-o", "IdentityFile=/keys/robot",
                  "-o", "ConnectTimeout=10", "-o", "ServerAliveInterval=1", "-o",
                  "ServerAliveCountMax=3", "-T", "robot@marvin", "--",
                  "/opt/oscar/bin/oscar-monitor --system 'my system.yaml' 'it'\\''s'"}));
}

// Program names as they are (a monitor maps them to its own copies).
std::string as_is(const std::string& program) { return program; }

SystemSpec one_module(const std::string& debug) {
  return SystemSpec::parse(
      YAML::Load("system: s\ndomain: 9\nmodules: [ { name: cam, kernels: [ { type: relay } ]" +
                 debug + " } ]"),
      "sys.yaml");
}

TEST(LaunchCommand, ModuleCommandNamesFileModuleIncarnationAndDomain) {
  const auto s = one_module("");
  EXPECT_EQ(
      module_command(s, s.modules[0], 3, as_is, "/logs"),
      (Argv{"oscar-run", "sys.yaml", "--module", "cam", "--incarnation", "3", "--domain", "9"}));
}

TEST(LaunchCommand, TheCoordinatorSectionStartsOscarCoordinatorAsAModule) {
  const auto s = SystemSpec::parse(
      YAML::Load("system: s\ndomain: 9\nmodules: [ { name: cam, kernels: [ { type: relay } ] } ]\n"
                 "coordinator: { applets: [] }"),
      "sys.yaml");
  ASSERT_EQ(s.modules.size(), 2u);
  EXPECT_EQ(module_command(s, s.modules[1], 1, as_is, "/logs"),
            (Argv{"oscar-coordinator", "sys.yaml", "--module", "coordinator", "--incarnation", "1",
                  "--domain", "9"}));
}

TEST(LaunchCommand, GdbserverListensOnLoopbackOnly) {
  const auto s = one_module(", debug: { gdbserver: 2345 }");
  const auto argv = module_command(s, s.modules[0], 1, as_is, "/logs");
  ASSERT_GE(argv.size(), 3u);
  EXPECT_EQ(argv[0], "gdbserver");
  EXPECT_EQ(argv[1], "127.0.0.1:2345");
  EXPECT_EQ(argv[2], "oscar-run");
}

TEST(LaunchCommand, ValgrindWritesItsLogBesideTheModules) {
  const auto s = one_module(", debug: { valgrind: [--leak-check=full] }");
  const auto argv = module_command(s, s.modules[0], 2, as_is, "/logs");
  EXPECT_EQ(
      Argv(argv.begin(), argv.begin() + 4),
      (Argv{"valgrind", "--log-file=/logs/cam.2.valgrind.log", "--leak-check=full", "oscar-run"}));
}

// The registry exempts a module from the hang watchdog by this, and `oscar ps` shows describe().
TEST(LaunchCommand, OnlyGdbserverHoldsTheProcessAndEachWrapperIsNamedForPs) {
  const auto gdb = one_module(", debug: { gdbserver: 2345 }").modules[0].debug;
  EXPECT_TRUE(gdb.holds_process());
  EXPECT_EQ(gdb.describe(), "gdbserver 127.0.0.1:2345");
  // valgrind slows a module down but never stops it: a silent one under valgrind is hung.
  const auto valgrind = one_module(", debug: { valgrind: [--leak-check=full] }").modules[0].debug;
  EXPECT_FALSE(valgrind.holds_process());
  EXPECT_EQ(valgrind.describe(), "valgrind");
  const auto plain = one_module("").modules[0].debug;
  EXPECT_FALSE(plain.holds_process());
  EXPECT_EQ(plain.describe(), "");
}

// A monitor builds the command of a start request from its own system file: the module must be
// one of the file's, on the monitor's host; the programs are the monitor's; a configuration to
// restore is the one argument that comes from the request.
TEST(LaunchCommand, AMonitorStartsOnlyModulesOfItsFileOnItsHost) {
  const auto s = SystemSpec::parse(
      YAML::Load("system: s\ndomain: 9\nhosts: { pc1: { local: true }, pc2: { netns: n2 } }\n"
                 "modules: [ { name: cam, host: pc1, kernels: [ { type: relay, name: r1 } ] },\n"
                 "           { name: far, host: pc2, kernels: [ { type: relay, name: r2 } ] } ]"),
      "sys.yaml");
  const auto mine = [](const std::string& p) { return "/opt/oscar/bin/" + p; };
  EXPECT_EQ(launch_command(s, "pc1", "cam", 2, "", "/logs", mine),
            (Argv{"/opt/oscar/bin/oscar-run", "sys.yaml", "--module", "cam", "--incarnation", "2",
                  "--domain", "9"}));
  EXPECT_EQ(launch_command(s, "pc1", "cam", 3, "rate: 5", "/logs", mine).back(), "rate: 5");
  try {
    launch_command(s, "pc1", "sh -c 'touch /tmp/x'", 1, "", "/logs", mine);
    ADD_FAILURE() << "a name that is no module was started";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("refused to start 'sh -c 'touch /tmp/x'': sys.yaml has no "
                                    "module of that name"));
  }
  try {
    launch_command(s, "pc1", "far", 1, "", "/logs", mine);
    ADD_FAILURE() << "another host's module was started";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("refused to start 'far': sys.yaml puts it on host 'pc2', "
                                    "this monitor watches 'pc1'"));
  }
}

}  // namespace
}  // namespace oscar
