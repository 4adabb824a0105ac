#include "host_roudi.hpp"

#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "oscar/process_util.hpp"
#include "zero_copy/mempools.hpp"
#include "zero_copy/roudi.hpp"

namespace oscar {
namespace {

using namespace std::chrono_literals;
constexpr auto kLookEvery = 100ms;
constexpr auto kShortLife = 5s;  // a RouDi that ends sooner is started again after a pause
constexpr auto kFirstPause = 500ms;
constexpr auto kLongestPause = 8s;
constexpr const char* kProgram = "iox-roudi";
// iceoryx 2.0's thread that monitors RouDi's processes and connects ports, every 100 ms.
constexpr std::string_view kDiscoveryThread = "Mon+Discover";

// How often the thread of process `pid` named `name` has gone to sleep so far (its voluntary
// context switches); nothing if the process has no such thread.
std::optional<unsigned long long> sleeps_of_thread(pid_t pid, std::string_view name) {
  std::error_code ec;
  for (const auto& task :
       std::filesystem::directory_iterator(fmt::format("/proc/{}/task", pid), ec)) {
    std::string comm;
    if (!std::getline(std::ifstream(task.path() / "comm"), comm) || comm != name) continue;
    std::ifstream status(task.path() / "status");
    for (std::string line; std::getline(status, line);) {
      constexpr std::string_view kKey = "voluntary_ctxt_switches:";
      if (line.starts_with(kKey)) return std::stoull(line.substr(kKey.size()));
    }
  }
  return std::nullopt;
}

}  // namespace

HostRoudi::HostRoudi(std::uint32_t chunks, const std::string& log_dir)
    : processes_(log_dir, SIGTERM), config_path_(log_dir + "/roudi.toml") {
  std::ofstream out(config_path_);
  out << zero_copy::roudi_config(zero_copy::plain_cue_mempools(chunks));
  if (!out.flush()) throw std::runtime_error(fmt::format("cannot write {}", config_path_));
}

HostRoudi::~HostRoudi() {
  // RouDi, stopping, sends SIGTERM to every process still registered with it, and SIGKILL a
  // second later (-k 1; iceoryx's default is 45 s) to those still there; then it removes its
  // shared memory and ends.
  for (const auto& x : processes_.stop_all(5s)) {
    spdlog::info("stopped RouDi (pid {}): {}", x.pid, x.describe());
  }
}

pid_t HostRoudi::pid() const {
  return processes_.children().empty() ? 0 : processes_.children().front().pid;
}

void HostRoudi::tick(Clock::time_point now) {
  if (now < next_look_) return;
  next_look_ = now + kLookEvery;
  for (const auto& x : processes_.reap()) {
    const bool short_life = now - started_at_ < kShortLife;
    pause_ = short_life ? std::clamp(pause_ * 2, std::chrono::milliseconds(kFirstPause),
                                     std::chrono::milliseconds(kLongestPause))
                        : 0ms;
    next_start_ = now + pause_;
    spdlog::warn("RouDi (pid {}) {} (its output: {})", x.pid, x.describe(),
                 processes_.log_path(kProgram));
    listening_said_ = false;
    discovery_sleeps_.reset();
  }
  const bool ours = pid() != 0;
  if (ours) kill_if_hung(now);
  if (zero_copy::roudi_running()) {
    if (ours && !listening_said_) {
      spdlog::info("RouDi runs (pid {}, mempools in {})", pid(), config_path_);
      listening_said_ = true;
    } else if (!ours && !foreign_said_) {
      spdlog::info(
          "a RouDi this monitor did not start runs on this host: its processes use that one "
          "(with its starter's mempools)");
      foreign_said_ = true;
    }
    return;
  }
  if (ours) return;  // still starting
  if (foreign_said_) {
    spdlog::warn("the RouDi this host's processes used is gone");
    foreign_said_ = false;
  }
  if (now >= next_start_) start(now);
}

void HostRoudi::kill_if_hung(Clock::time_point now) {
  const auto sleeps = sleeps_of_thread(pid(), kDiscoveryThread);
  if (!sleeps) return;  // starting
  if (sleeps != discovery_sleeps_) {
    discovery_sleeps_ = sleeps;
    discovery_slept_at_ = now;
    return;
  }
  if (now - discovery_slept_at_ < kHungAfter) return;
  spdlog::error(
      "RouDi (pid {}) hangs: its discovery thread has not run for {} s (iceoryx 2.0 waits for "
      "good on a lock of a process that died holding it); killing it",
      pid(), kHungAfter.count());
  ::kill(pid(), SIGKILL);
}

void HostRoudi::start(Clock::time_point now) {
  started_at_ = now;
  try {
    const auto pid =
        processes_.start(kProgram, started_ + 1, {kProgram, "-c", config_path_, "-k", "1"});
    ++started_;
    failure_said_ = false;
    if (started_ == 1) {
      spdlog::info("started RouDi (pid {})", pid);
    } else {
      spdlog::warn(
          "started RouDi again (pid {}): modules that joined the RouDi before end and their "
          "registry starts them again (iceoryx 2.0 cannot move a process to a new RouDi)",
          pid);
    }
  } catch (const std::runtime_error& e) {
    pause_ = std::chrono::milliseconds(kLongestPause);
    next_start_ = now + pause_;
    if (failure_said_) return;
    failure_said_ = true;
    if (!find_on_path(kProgram)) {
      spdlog::error(
          "zero_copy: iox-roudi is not installed on this host (Debian package iceoryx): its cues "
          "go serialized through DDS; looking for it again every {} s",
          std::chrono::duration_cast<std::chrono::seconds>(pause_).count());
    } else {
      spdlog::error("zero_copy: {}; trying again every {} s", e.what(),
                    std::chrono::duration_cast<std::chrono::seconds>(pause_).count());
    }
  }
}

}  // namespace oscar
