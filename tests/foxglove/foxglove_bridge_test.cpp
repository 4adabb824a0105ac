// oscar bridge foxglove against a booted system, checked by Foxglove's own client libraries
// (bridge_client.js with @foxglove/ws-protocol and @foxglove/omgidl-serialization, run by
// Node.js). Skipped where node or npm is missing.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "booted_system.hpp"  // tests/integration

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using test::Process;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

// The program's path on $PATH, or "".
std::string on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const auto candidate = fs::path(dir) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return "";
}

std::string read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Installs the locked npm packages into the build tree with `npm ci`, unless the lock file
// installed there last time is this one. Returns npm's output on failure, "" on success.
std::string install_client_packages(const std::string& npm) {
  const fs::path source(OSCAR_FOXGLOVE_TEST_DIR), target(OSCAR_FOXGLOVE_NPM_DIR);
  const auto lock = read(source / "package-lock.json");
  if (fs::exists(target / "node_modules" / ".package-lock.json") &&
      read(target / "package-lock.json") == lock) {
    return "";
  }
  fs::create_directories(target);
  for (const auto* file : {"package.json", "package-lock.json"}) {
    fs::copy_file(source / file, target / file, fs::copy_options::overwrite_existing);
  }
  Process ci(
      {npm, "ci", "--prefix", target.string(), "--no-audit", "--no-fund", "--loglevel=error"},
      test::temp_path("npm_ci") + ".log");
  const auto rc = ci.wait(300s);
  return rc == 0 ? "" : "npm ci failed:\n" + ci.output();
}

// The port the bridge printed it serves on, once it did (0 if it did not within 20 s).
int served_port(const Process& bridge) {
  const std::regex served("ws://127\\.0\\.0\\.1:([0-9]+)");
  for (int i = 0; i < 400; ++i) {
    std::smatch m;
    const auto out = bridge.output();
    if (std::regex_search(out, m, served)) return std::stoi(m[1]);
    std::this_thread::sleep_for(50ms);
  }
  return 0;
}

TEST(FoxgloveBridge, ServesABootedSystemToFoxglovesOwnClient) {
  const auto node = on_path("node"), npm = on_path("npm");
  if (node.empty() || npm.empty()) {
    GTEST_SKIP() << "node/npm not found: this test runs Foxglove's client libraries on Node.js "
                    "(Debian: apt-get install nodejs npm)";
  }
  const auto install_error = install_client_packages(npm);
  ASSERT_EQ(install_error, "");

  BootedSystem system("foxglove", R"(
system: viewed
lease: 1s
modules:
  - name: sources
    kernels: [ { type: bench_source, name: sig, params: { type: Bool } } ]
    mode: deactivated
  - name: camera
    kernels: [ { type: bench_source, name: cam, params: { type: GvImage, dx: 640, dy: 480 } } ]
    mode: deactivated
)");
  system.running();
  for (const auto& [module, kernel, mode] :
       {std::tuple{"sources", "sig", "continuous:20ms"}, {"camera", "cam", "continuous:50ms"}}) {
    const auto reply = system.configure(module, CMD_ACTIVATE, {kernel, mode});
    ASSERT_TRUE(reply.ok()) << kernel << ": " << reply.error();
  }
  const auto domain = std::to_string(test::test_domain());
  Process bridge(
      {test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0", "--queue-messages", "4"},
      test::temp_path("bridge") + ".log");
  const auto port = served_port(bridge);
  ASSERT_NE(port, 0) << bridge.output();

  ::setenv("NODE_PATH", (fs::path(OSCAR_FOXGLOVE_NPM_DIR) / "node_modules").c_str(), 1);
  // After --late: the command of a module the client starts later (its topic appears then).
  Process client({node, std::string(OSCAR_FOXGLOVE_TEST_DIR) + "/bridge_client.js", "--url",
                  "ws://127.0.0.1:" + std::to_string(port), "--late", test::bin("oscar-run"),
                  "--name", "late", "--domain", domain, "-k", "bench_source:late", "-p",
                  "late.type=Bool", "-m", "continuous:50ms"},
                 test::temp_path("bridge_client") + ".log");
  const auto rc = client.wait(180s);
  std::cout << client.output();
  EXPECT_EQ(rc, 0) << client.output() << "\nbridge:\n" << bridge.output();
  for (const auto pid : test::processes_mentioning("bench_source:late")) ::kill(pid, SIGKILL);

  // The bridge read the topics only while subscribed, and said whom it dropped what for.
  const auto log = bridge.output();
  EXPECT_THAT(log, HasSubstr("subscribes to oscar/cue/sig/out"));
  EXPECT_THAT(log, ::testing::ContainsRegex("reads too slowly: dropped the oldest [0-9]+ of "
                                            "oscar/cue/cam/out"));
  EXPECT_THAT(log, HasSubstr("oscar/cue/late/out is gone"));
  bridge.stop();
  EXPECT_THAT(bridge.output(), HasSubstr("oscar bridge: stopped"));
}

}  // namespace
}  // namespace oscar
