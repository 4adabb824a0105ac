#pragma once
// A system booted by `oscar boot` for a test: the YAML written to a file, boot running as a
// child, and a registry client on the same domain to watch the system state.

#include <signal.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "oscar/config_client.hpp"
#include "oscar/registry/registry_client.hpp"
#include "process.hpp"  // tests/common

namespace oscar::test {

inline std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / (name + "_" + std::to_string(getpid())))
      .string();
}

class BootedSystem {
 public:
  /// Writes `yaml` (without domain: the test's own is used) and runs oscar-boot on it.
  BootedSystem(const std::string& name, const std::string& yaml, std::string domain_flag = "")
      : file_(temp_path(name) + ".yaml"), log_dir_(temp_path(name) + "_logs") {
    std::filesystem::remove_all(log_dir_);
    std::ofstream(file_) << yaml;
    participant_ = std::make_unique<DdsParticipant>(test_domain(), "test:" + name);
    client_ = std::make_unique<RegistryClient>(*participant_, "test");
    config_ = std::make_unique<ConfigClient>(*participant_, "coordinator");
    boot_ = std::make_unique<Process>(
        std::vector<std::string>{bin("oscar-boot"), file_, "--domain",
                                 domain_flag.empty() ? std::to_string(test_domain()) : domain_flag,
                                 "--log-dir", log_dir_, "--timeout", "30"},
        temp_path(name) + "_boot.log");
  }
  ~BootedSystem() {
    if (boot_) boot_->stop();
  }

  const std::string& file() const { return file_; }
  const std::string& log_dir() const { return log_dir_; }
  Process& boot() { return *boot_; }
  RegistryClient& registry() { return *client_; }
  ConfigClient& config() { return *config_; }

  /// The first state satisfying `pred` within `timeout`; fails the test otherwise.
  SystemState wait_for(const std::function<bool(const SystemState&)>& pred,
                       std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    auto s = client_->wait_for(pred, timeout);
    if (!s) {
      const auto last = client_->latest();
      ADD_FAILURE() << "the system did not reach the expected state; last: "
                    << (last ? last->state() + " (" + last->message() + ")" : "none")
                    << "\nboot output:\n"
                    << boot_->output();
      return last.value_or(SystemState{});
    }
    return *s;
  }
  SystemState running() {
    return wait_for([](const SystemState& s) { return s.state() == "running"; });
  }

  /// Stops boot as Ctrl-C would and returns its exit code.
  std::optional<int> shut_down() {
    kill(boot_->pid(), SIGINT);
    return boot_->wait(std::chrono::seconds(40));
  }

 private:
  std::string file_, log_dir_;
  std::unique_ptr<DdsParticipant> participant_;
  std::unique_ptr<RegistryClient> client_;
  std::unique_ptr<ConfigClient> config_;
  std::unique_ptr<Process> boot_;
};

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

/// True if a process with that pid still exists (and is not a zombie).
inline bool alive(long pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

/// Pids of processes whose command line mentions `text`.
inline std::vector<long> processes_mentioning(const std::string& text) {
  std::vector<long> out;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const auto name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(e.path() / "cmdline");
    std::string cmd((std::istreambuf_iterator<char>(in)), {});
    if (cmd.find(text) != std::string::npos && alive(std::stol(name)))
      out.push_back(std::stol(name));
  }
  return out;
}

}  // namespace oscar::test
