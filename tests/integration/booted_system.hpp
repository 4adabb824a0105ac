#pragma once
// A system booted for an integration test from YAML text: oscar::testing::SystemUnderTest (the
// fixture users get, docs/testing.md) on the YAML written to a file, on this test's domain.

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "oscar/process_util.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/testing/booted_system.hpp"
#include "proc.hpp"     // tests/common
#include "process.hpp"  // tests/common

namespace oscar::test {

class BootedSystem : public testing::SystemUnderTest {
 public:
  /// Writes `yaml` to a file and boots it on `domain` (default: test_domain(); the file's own
  /// is ignored).
  BootedSystem(const std::string& name, const std::string& yaml, int domain = -1)
      : SystemUnderTest(write(name, yaml), {.domain = domain < 0 ? test_domain() : domain,
                                            .log_dir = temp_path(name) + "_logs"}) {}
  /// The same with more of boot's options (e.g. a keystore); domain and log folder as above
  /// unless `options` gives them.
  BootedSystem(const std::string& name, const std::string& yaml, testing::BootOptions options)
      : SystemUnderTest(write(name, yaml), with_defaults(name, std::move(options))) {}
  ~BootedSystem() {
    shut_down();
    std::error_code ec;
    std::filesystem::remove(file(), ec);
  }

  /// The first state satisfying `pred` within `timeout`; fails the test otherwise.
  SystemState wait_for(const std::function<bool(const SystemState&)>& pred,
                       std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    if (auto s = SystemUnderTest::wait_for(pred, timeout)) return *s;
    const auto last = registry().latest();
    ADD_FAILURE() << "the system did not reach the expected state; last: "
                  << (last ? last->state() + " (" + last->message() + ")" : "none")
                  << "\nboot output:\n"
                  << boot_output();
    return last.value_or(SystemState{});
  }
  SystemState running() {
    return wait_for([](const SystemState& s) { return s.state() == "running"; });
  }

 private:
  static testing::BootOptions with_defaults(const std::string& name, testing::BootOptions o) {
    if (o.domain < 0) o.domain = test_domain();
    if (o.log_dir.empty()) o.log_dir = temp_path(name) + "_logs";
    return o;
  }
  static std::string write(const std::string& name, const std::string& yaml) {
    const auto file = temp_path(name) + ".yaml";
    std::filesystem::remove_all(temp_path(name) + "_logs");
    std::ofstream(file) << yaml;
    return file;
  }
};

/// A keystore for the system `yaml` in `keystore`, made by `oscar security init` (each test makes
/// its own: nothing secret is committed).
inline void make_keystore(const std::string& name, const std::string& yaml,
                          const std::filesystem::path& keystore) {
  const auto file = temp_path(name + "_keys") + ".yaml";
  std::ofstream(file) << yaml;
  Process init({bin("oscar-security"), "init", file, "--keystore", keystore.string()},
               temp_path(name + "_keys.log"));
  ASSERT_EQ(init.wait(std::chrono::seconds(60)), 0) << init.output();
  std::filesystem::remove(file);
}

inline const ModuleEntry* entry(const SystemState& s, const std::string& module) {
  for (const auto& m : s.modules()) {
    if (m.name() == module) return &m;
  }
  return nullptr;
}

inline const KernelState* kernel_state(const ModuleEntry& m, const std::string& kernel) {
  for (const auto& k : m.state().kernels()) {
    if (k.name() == kernel) return &k;
  }
  return nullptr;
}

/// True if a process with that pid still has a thread that is not a zombie.
inline bool alive(long pid) { return process_lives(static_cast<pid_t>(pid)); }

/// Pids of processes whose command line mentions `text`.
inline std::vector<long> processes_mentioning(const std::string& text) {
  std::vector<long> out;
  for (const long pid : listed_pids()) {
    if (proc_file(pid, "cmdline").find(text) != std::string::npos && alive(pid)) out.push_back(pid);
  }
  return out;
}

}  // namespace oscar::test
