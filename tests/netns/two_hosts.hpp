#pragma once
// Boots one of the shipped two-host system files (hosts pc1 and pc2) on two test hosts for a
// while: boot and the registry run on pc1; the lease is 1 s as in the other booted-system tests
// on a loaded machine.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>

#include "process.hpp"
#include "source_tree.hpp"
#include "test_hosts.hpp"

namespace oscar::test {

struct TwoHostRun {
  std::optional<int> exit_code;  ///< none: boot did not end in time
  std::string boot_output;
  std::string log_dir;  ///< pc1/<module>.log, pc2/<module>.log
};

inline TwoHostRun boot_on_two_hosts(TestHosts& hosts, const std::string& config,
                                    const std::string& name, int seconds) {
  auto root = YAML::LoadFile(oscar::testing::source_path("config/") + config);
  root.remove("domain");
  root["lease"] = "1s";
  root["hosts"]["pc1"]["address"] = hosts.address(1);
  root["hosts"]["pc2"]["netns"] = hosts.netns(2);
  root["hosts"]["pc2"]["address"] = hosts.address(2);
  const auto file = temp_path(name) + ".yaml";
  {
    YAML::Emitter out;
    out << root;
    std::ofstream(file) << out.c_str();
  }
  TwoHostRun run;
  run.log_dir = temp_path(name + "_logs");
  std::filesystem::remove_all(run.log_dir);
  auto argv = hosts.on(1);
  argv.insert(argv.end(),
              {bin("oscar-boot"), file, "--domain", std::to_string(test_domain()), "--log-dir",
               run.log_dir, "--timeout", "40", "--duration", std::to_string(seconds)});
  Process boot(argv, temp_path(name + "_boot.log"));
  run.exit_code = boot.wait(std::chrono::seconds(seconds + 90));
  run.boot_output = boot.output();
  return run;
}

}  // namespace oscar::test
