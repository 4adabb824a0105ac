// oscar bridge foxglove against a booted system, checked by Foxglove's own client libraries
// (bridge_client.js with @foxglove/ws-protocol, @foxglove/omgidl-serialization and
// @foxglove/schemas, run by Node.js): one bridge as started by default, one with
// --allow-config; and the bridge's schemas for Foxglove's types held to the published ones
// (schema_checks.js). Skipped where node or npm is missing.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "booted_system.hpp"  // tests/integration
#include "foxglove_messages.hpp"
#include "jpeg_encoder.hpp"
#include "json_schemas.hpp"
#include "source_tree.hpp"

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

// This folder's Node scripts, and the npm packages installed for them in the build tree.
std::string script(const std::string& name) {
  return oscar::testing::source_path("tests/foxglove/") + name;
}
fs::path npm_dir() { return oscar::testing::build_path("tests/foxglove/npm"); }

std::string read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Installs the locked npm packages into the build tree with `npm ci`, unless the lock file
// installed there last time is this one. Returns npm's output on failure, "" on success.
std::string install_client_packages(const std::string& npm) {
  const fs::path source = oscar::testing::source_path("tests/foxglove"), target = npm_dir();
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

// The schemas the bridge advertises for Foxglove's types are its own, declaring only the fields
// it sends. Each must follow Foxglove's published schema of that name: every field it declares
// exists there at the same place with the same type, and it declares all the published one
// requires; and what the encoders make conforms to both and sends nothing undeclared. A field
// whose name or type drifts from Foxglove's fails here.
TEST(FoxgloveBridge, ItsSchemasForFoxglovesTypesFollowThePublishedOnes) {
  const auto node = on_path("node"), npm = on_path("npm");
  if (node.empty() || npm.empty()) GTEST_SKIP() << "node/npm not found (see the test below)";
  ASSERT_EQ(install_client_packages(npm), "");
  using nlohmann::json;
  CueHeader header;
  header.stamps({1'700'000'000'123'456'789ull});
  header.source("cam/out");
  GvImage grey;
  grey.header(header);
  grey.dx(4);
  grey.dy(2);
  grey.image({0, 1, 2, 3, 252, 253, 254, 255});
  CameraImage camera;
  camera.header(header);
  camera.camera_id("cam_a");
  camera.encoding("mono8");
  camera.width(1);
  camera.height(3);
  camera.data({7, 8, 9});
  LandmarkPose pose;
  pose.header(header);
  pose.valid(true);
  Pose3 p;
  p.t({0.5, -1.0, 2.0});
  p.q({1.0, 0.0, 0.0, 0.0});
  pose.pose(p);
  json messages = {{"foxglove.RawImage", json::array()},
                   {"foxglove.CompressedImage", json::array()},
                   {"foxglove.PoseInFrame", json::array()},
                   {"foxglove.SceneUpdate", json::array()}};
  messages["foxglove.RawImage"].push_back(json::parse(*bridge::raw_image_json(grey)));
  messages["foxglove.RawImage"].push_back(json::parse(*bridge::raw_image_json(camera)));
  if (bridge::jpeg_available()) {
    messages["foxglove.CompressedImage"].push_back(
        json::parse(*bridge::compressed_image_json(grey, 80)));
    messages["foxglove.CompressedImage"].push_back(
        json::parse(*bridge::compressed_image_json(camera, 80)));
  } else {
    messages.erase("foxglove.CompressedImage");
  }
  messages["foxglove.PoseInFrame"].push_back(json::parse(*bridge::pose_in_frame_json(pose)));
  for (const auto& [job, broken] : {std::pair{"j1", false}, {"", false}, {"", true}}) {
    RobotState robot;
    robot.header(header);
    robot.robot("r1");
    robot.radius(0.3);
    robot.x(1.0);
    robot.y(-2.0);
    robot.heading(0.5);
    robot.speed(0.75);
    RobotJob j;
    j.id(job);
    robot.job(j);
    robot.broken(broken);
    robot.fault(broken ? "motor" : "");
    messages["foxglove.SceneUpdate"].push_back(json::parse(*bridge::scene_update_json(robot)));
  }
  json schemas = json::object();
  for (const auto& entry : messages.items()) {
    schemas[entry.key()] = json::parse(bridge::json_schema(entry.key()));
  }
  const auto schemas_file = test::temp_path("foxglove_schemas") + ".json";
  const auto messages_file = test::temp_path("foxglove_messages") + ".json";
  std::ofstream(schemas_file) << schemas.dump(2);
  std::ofstream(messages_file) << messages.dump(2);

  ::setenv("NODE_PATH", (npm_dir() / "node_modules").c_str(), 1);
  Process check(
      {node, script("schema_checks.js"), "--schemas", schemas_file, "--messages", messages_file},
      test::temp_path("schema_checks") + ".log");
  EXPECT_EQ(check.wait(60s), 0) << check.output();
  std::cout << check.output();
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
plugins: [ )" + test::build_dir() + R"(/lib/oscar/test_plugins/liboscar_kernel_acme_arm.so ]
modules:
  - name: sources
    kernels: [ { type: bench_source, name: sig, params: { type: Bool } } ]
    mode: deactivated
  - name: camera
    kernels: [ { type: bench_source, name: cam, params: { type: GvImage, dx: 640, dy: 480 } } ]
    mode: deactivated
  - name: plain_camera
    kernels: [ { type: bench_source, name: pcam, params: { type: PlainGvImage, dx: 320, dy: 240 } } ]
    mode: deactivated
  - name: robot
    kernels: [ { type: robot_sim, name: r7, params: { start_x: 3, start_y: 4, radius: 0.3 } } ]
    mode: deactivated
  - name: arm
    kernels: [ { type: acme_arm, name: arm, params: { tool: welder } } ]
    mode: { continuous: 100ms }
)");
  system.running();
  for (const auto& [module, kernel, mode] : {std::tuple{"sources", "sig", "continuous:20ms"},
                                             {"camera", "cam", "continuous:50ms"},
                                             {"plain_camera", "pcam", "continuous:100ms"},
                                             {"robot", "r7", "continuous:100ms"}}) {
    const auto reply = system.configure(module, CMD_ACTIVATE, {kernel, mode});
    ASSERT_TRUE(reply.ok()) << kernel << ": " << reply.error();
  }
  const auto domain = std::to_string(test::test_domain());
  Process bridge(
      {test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0", "--queue-messages", "4"},
      test::temp_path("bridge") + ".log");
  const auto port = served_port(bridge);
  ASSERT_NE(port, 0) << bridge.output();
  Process config_bridge(
      {test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0", "--allow-config"},
      test::temp_path("config_bridge") + ".log");
  const auto config_port = served_port(config_bridge);
  ASSERT_NE(config_port, 0) << config_bridge.output();

  ::setenv("NODE_PATH", (npm_dir() / "node_modules").c_str(), 1);
  // After --late: the command of a module the client starts later (its topic appears then).
  Process client(
      {node, script("bridge_client.js"), "--url", "ws://127.0.0.1:" + std::to_string(port),
       "--config-url", "ws://127.0.0.1:" + std::to_string(config_port),
       bridge::jpeg_available() ? "--expect-jpeg" : "--no-jpeg", "--late", test::bin("oscar-run"),
       "--name", "late", "--domain", domain, "-k", "bench_source:late", "-p", "late.type=Bool",
       "-m", "continuous:50ms"},
      test::temp_path("bridge_client") + ".log");
  const auto rc = client.wait(240s);
  std::cout << client.output();
  EXPECT_EQ(rc, 0) << client.output() << "\nbridge:\n"
                   << bridge.output() << "\nbridge with --allow-config:\n"
                   << config_bridge.output();
  for (const auto pid : test::processes_mentioning("bench_source:late")) ::kill(pid, SIGKILL);

  // A bridge that sends each client at most 5 images per second of a channel: the 20 Hz camera
  // arrives at about 5 Hz, the 50 Hz Bool untouched, and the client is told why.
  Process throttled(
      {test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0", "--image-rate", "5"},
      test::temp_path("throttled_bridge") + ".log");
  const auto throttled_port = served_port(throttled);
  ASSERT_NE(throttled_port, 0) << throttled.output();
  Process rate_client(
      {node, script("image_rate.js"), "--url", "ws://127.0.0.1:" + std::to_string(throttled_port),
       "--image", "oscar/cue/cam/out", "--bool", "oscar/cue/sig/out"},
      test::temp_path("image_rate_client") + ".log");
  ASSERT_EQ(rate_client.wait(60s), 0) << rate_client.output();
  const auto rates = nlohmann::json::parse(rate_client.output());
  EXPECT_GE(rates["images_per_s"].get<double>(), 3.5) << rates;
  EXPECT_LE(rates["images_per_s"].get<double>(), 6.0) << rates;
  EXPECT_GE(rates["bools_per_s"].get<double>(), 25.0) << rates;
  EXPECT_TRUE(rates["told"].get<bool>()) << rates;
  throttled.stop();

  // A bridge whose every conversion takes a second more (its test hook): the image side
  // channels fall to about one message a second, the newer samples skipped and counted, while
  // the raw Bool channel of the same client goes on at its rate. Conversion on the I/O thread
  // would hold every raw message up for the encoder (50 Bools a second would become a few).
  Process slow({test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0",
                "--test-conversion-delay-ms", "1000"},
               test::temp_path("slow_conversion_bridge") + ".log");
  const auto slow_port = served_port(slow);
  ASSERT_NE(slow_port, 0) << slow.output();
  std::vector<std::string> slow_args{node,     script("slow_conversion.js"),
                                     "--url",  "ws://127.0.0.1:" + std::to_string(slow_port),
                                     "--bool", "oscar/cue/sig/out",
                                     "--side", "foxglove/cam/out"};
  if (bridge::jpeg_available()) {
    slow_args.insert(slow_args.end(), {"--side", "foxglove/cam/out/compressed"});
  }
  Process slow_client(slow_args, test::temp_path("slow_conversion_client") + ".log");
  ASSERT_EQ(slow_client.wait(60s), 0) << slow_client.output();
  std::cout << "slow conversion: " << slow_client.output();
  const auto slowed = nlohmann::json::parse(slow_client.output());
  EXPECT_GE(slowed["bools_per_s"].get<double>(), 40.0) << slowed;
  EXPECT_LT(slowed["max_bool_gap_ms"].get<double>(), 1000.0) << slowed;
  EXPECT_GT(slowed["side_per_s"]["foxglove/cam/out"].get<double>(), 0.0) << slowed;
  EXPECT_LE(slowed["side_per_s"]["foxglove/cam/out"].get<double>(), 1.5) << slowed;
  EXPECT_GT(slowed["skipped"]["foxglove/cam/out"].get<double>(), 10.0) << slowed;
  slow.stop();

  // The command services follow their module: killed, its services go; restarted by the
  // registry, they come back under the same ids.
  const auto logged = [&](const std::string& text, int times) {
    for (int i = 0; i < 600; ++i) {
      const auto out = config_bridge.output();
      int n = 0;
      for (auto at = out.find(text); at != std::string::npos; at = out.find(text, at + 1)) ++n;
      if (n >= times) return true;
      std::this_thread::sleep_for(50ms);
    }
    return false;
  };
  const auto robot_running = system.wait_for([](const SystemState& s) {
    const auto* m = test::entry(s, "robot");
    return m && m->status() == "running";
  });
  const auto* robot = test::entry(robot_running, "robot");
  ASSERT_NE(robot, nullptr);
  const auto incarnation = robot->incarnation();
  ASSERT_EQ(::kill(static_cast<pid_t>(robot->pid()), SIGKILL), 0);
  EXPECT_TRUE(logged("service 2 oscar/robot/r7/propose is gone", 1)) << config_bridge.output();
  system.wait_for([&](const SystemState& s) {
    const auto* m = test::entry(s, "robot");
    return m && m->incarnation() > incarnation && m->status() == "running";
  });
  EXPECT_TRUE(logged("service 2 oscar/robot/r7/propose (oscar::Trajectory)", 2))
      << config_bridge.output();

  // The bridge read the topics only while subscribed, and said whom it dropped what for.
  const auto log = bridge.output();
  EXPECT_THAT(log, HasSubstr("subscribes to oscar/cue/sig/out"));
  // One line per report names every channel with drops since the last, in any order.
  EXPECT_THAT(log, ::testing::ContainsRegex("reads too slowly: dropped the oldest ([0-9]+ of "
                                            "[^,\n]+, )*[0-9]+ of oscar/cue/cam/out"));
  EXPECT_THAT(log, HasSubstr("oscar/cue/late/out is gone"));
  // The image side channel converted only while the client subscribed to it: once.
  const std::regex converting(
      "bridge: converting oscar/cue/cam/out for foxglove/cam/out \\(subscribed\\)");
  EXPECT_EQ(std::distance(std::sregex_iterator(log.begin(), log.end(), converting),
                          std::sregex_iterator()),
            1)
      << log;
  EXPECT_THAT(log, ::testing::ContainsRegex(
                       "stopped converting oscar/cue/cam/out for foxglove/cam/out after [1-9]"));
  if (bridge::jpeg_available()) {
    EXPECT_THAT(log, ::testing::ContainsRegex("stopped converting oscar/cue/cam/out for "
                                              "foxglove/cam/out/compressed after [1-9]"));
  }
  // Malformed calls did not stop the bridge that takes them; the valid one was carried out.
  const auto config_log = config_bridge.output();
  EXPECT_THAT(config_log, HasSubstr("oscar/config robot set-cycle r7 50ms: accepted"));
  EXPECT_THAT(config_log, HasSubstr("oscar/robot/r7/commit robot command r7 commit: accepted"));
  bridge.stop();
  config_bridge.stop();
  EXPECT_THAT(bridge.output(), HasSubstr("oscar bridge: stopped"));
  EXPECT_THAT(config_bridge.output(), HasSubstr("oscar bridge: stopped"));
}

// In a secured system (docs/security.md) the bridge with --allow-config joins as `operator_boot`,
// whose permissions let it write configuration commands: Foxglove's client changes a module's
// cycle through it. A keystore holding only the look-only `operator` serves a bridge without the
// flag, and refuses one with it, naming the identity it lacks.
TEST(FoxgloveBridge, InASecuredSystemConfiguresOnlyAsTheIdentityOperatorBoot) {
  const auto node = on_path("node"), npm = on_path("npm");
  if (node.empty() || npm.empty()) GTEST_SKIP() << "node/npm not found (see the test above)";
  ASSERT_EQ(install_client_packages(npm), "");
  const std::string yaml = R"(
system: secured_view
lease: 1s
modules:
  - name: sources
    kernels: [ { type: bench_source, name: sig, params: { type: Bool } } ]
    mode: { continuous: 100ms }
)";
  const fs::path keystore = test::temp_path("foxglove_keystore");
  fs::remove_all(keystore);
  test::make_keystore("foxglove", yaml, keystore);
  ASSERT_FALSE(HasFatalFailure());
  const auto domain = std::to_string(test::test_domain());
  {
    testing::BootOptions options;
    options.keystore = keystore.string();
    BootedSystem system("foxglove_secured", yaml, options);
    system.running();
    Process bridge(
        {test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0", "--allow-config"},
        test::temp_path("secured_bridge") + ".log");
    const auto port = served_port(bridge);
    ASSERT_NE(port, 0) << bridge.output();
    ::setenv("NODE_PATH", (npm_dir() / "node_modules").c_str(), 1);
    Process call(
        {node, script("config_call.js"), "--url", "ws://127.0.0.1:" + std::to_string(port),
         "--request", R"({"module": "sources", "command": "set-cycle", "args": ["sig", "50ms"]})"},
        test::temp_path("secured_call") + ".log");
    EXPECT_EQ(call.wait(30s), 0) << call.output() << "\nbridge:\n" << bridge.output();
    EXPECT_THAT(call.output(), HasSubstr(R"("cycle_ms":50.0)"));
    system.wait_for([](const SystemState& s) {
      const auto* m = test::entry(s, "sources");
      const auto* k = m ? test::kernel_state(*m, "sig") : nullptr;
      return k && k->cycle_ns() == 50'000'000;
    });
    bridge.stop();
  }
  const fs::path look = test::temp_path("foxglove_look_keystore");
  fs::remove_all(look);
  fs::create_directories(look / "identities");
  fs::copy(keystore / "identities" / "operator", look / "identities" / "operator",
           fs::copy_options::recursive);
  fs::copy(keystore / "public", look / "public", fs::copy_options::recursive);
  ::setenv("OSCAR_KEYSTORE", look.c_str(), 1);
  Process acting(
      {test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0", "--allow-config"},
      test::temp_path("acting_bridge") + ".log");
  Process looking({test::bin("oscar-bridge"), "foxglove", "-d", domain, "--port", "0"},
                  test::temp_path("looking_bridge") + ".log");
  ::unsetenv("OSCAR_KEYSTORE");
  EXPECT_EQ(acting.wait(20s), 1) << acting.output();
  EXPECT_THAT(acting.output(), HasSubstr("identity 'operator_boot' has no"));
  EXPECT_NE(served_port(looking), 0) << looking.output();
  looking.stop();
  fs::remove_all(look);
  fs::remove_all(keystore);
}

}  // namespace
}  // namespace oscar
