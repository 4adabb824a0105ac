#include "sequencer_kernel.hpp"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include <oscar/config_client.hpp>
#include <oscar/dds_participant.hpp>
#include <oscar/kernel_registry.hpp>
#include <oscar/module_spec.hpp>
#include <oscar/network.hpp>

namespace oscar::modules {
namespace {
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string part; std::getline(in, part, sep);) {
    if (!part.empty()) out.push_back(part);
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> parse_targets(const std::string& text,
                                                               const char* param) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& item : split(text, ',')) {
    const auto colon = item.find(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == item.size()) {
      throw std::invalid_argument(
          fmt::format("parameter '{}': '{}' is not 'module:kernel'", param, item));
    }
    out.emplace_back(item.substr(0, colon), item.substr(colon + 1));
  }
  return out;
}

bool is_frame_mode(const std::string& m) { return m == "full" || m == "half" || m == "quarter"; }
}  // namespace

void Sequencer::Params::describe(ParamSpec& spec) {
  spec.field("steps", steps, "kernels to trigger each cycle, in order: 'module:kernel,...'");
  spec.field("framegrabbers", framegrabbers, "framegrabbers it configures: 'module:kernel,...'");
  spec.field("frame_mode", frame_mode, "frame mode it sets ('' = leave them)")
      .one_of({"", "full", "half", "quarter"});
  spec.field("frame_mode_schedule", frame_mode_schedule,
             "switch modes by cycles, repeating: 'quarter:20,half:20' ('' = none)");
  spec.field("timeout", timeout, "how long to wait for a module's reply").at_least(0.001);
}

Sequencer::Sequencer(KernelSetup& setup) {
  setup.params(params_);
  on_params_changed();
}

Sequencer::~Sequencer() { on_deactivate(); }

void Sequencer::on_params_changed() {
  steps_ = parse_targets(params_.steps, "steps");
  grabbers_ = parse_targets(params_.framegrabbers, "framegrabbers");
  schedule_.clear();
  for (const auto& item : split(params_.frame_mode_schedule, ',')) {
    const auto colon = item.find(':');
    const auto mode = item.substr(0, colon);
    std::uint64_t cycles = 0;
    if (colon != std::string::npos) cycles = std::strtoull(item.c_str() + colon + 1, nullptr, 10);
    if (!is_frame_mode(mode) || cycles == 0) {
      throw std::invalid_argument(fmt::format(
          "parameter 'frame_mode_schedule': '{}' is not 'full|half|quarter:<cycles>'", item));
    }
    schedule_.emplace_back(mode, cycles);
  }
  if ((!params_.frame_mode.empty() || !schedule_.empty()) && grabbers_.empty()) {
    throw std::invalid_argument(
        "parameter 'frame_mode' or 'frame_mode_schedule' needs 'framegrabbers' to configure");
  }
}

// The domain, system file and host come from oscar-run (it exports them before the module
// starts), so the sequencer joins the system it runs in.
void Sequencer::connect() {
  if (client_) return;
  const int domain = domain_from_env(0);
  NetworkConfig network;
  const char* file = std::getenv("OSCAR_SYSTEM_FILE");
  const char* host = std::getenv("OSCAR_HOST");
  if (file && *file && host && *host) {
    network = NetworkConfig::for_host(load_yaml_file(file), host);
  }
  participant_ = std::make_unique<DdsParticipant>(domain, "oscar:sequencer", network);
  client_ = std::make_unique<ConfigClient>(*participant_, "coordinator");
  std::lock_guard lock(mutex_);
  stop_ = false;
}

void Sequencer::on_activate() { connect(); }

void Sequencer::on_deactivate() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    for (auto& [module, lane] : lanes_) lane.queue.clear();
  }
  wake_.notify_all();
  for (auto& [module, lane] : lanes_) {
    if (lane.thread.joinable()) lane.thread.join();
  }
  lanes_.clear();
  sequences_ = 0;  // a new activation finds its modules again
  first_sequence_told_ = false;
  client_.reset();
  participant_.reset();
  applied_mode_.clear();
}

bool Sequencer::idle() {
  std::lock_guard lock(mutex_);
  return !busy();
}

bool Sequencer::busy() const {
  for (const auto& [module, lane] : lanes_) {
    if (!lane.queue.empty()) return true;
  }
  return false;
}

void Sequencer::worker_loop(const std::string& module) {
  std::unique_lock lock(mutex_);
  auto& queue = lanes_.at(module).queue;  // std::map: the reference stays valid
  while (!stop_) {
    if (queue.empty()) {
      wake_.wait(lock);
      continue;
    }
    const Command c = queue.front();
    const auto timeout = timeout_;
    lock.unlock();
    std::string error;
    try {
      const auto reply = client_->send(c.module, c.kind, c.args, timeout);
      if (!reply.ok()) error = reply.error();
    } catch (const std::exception& e) {
      error = e.what();
    }
    lock.lock();
    if (stop_) break;  // on_deactivate() emptied the queue while the command was on its way
    queue.pop_front();
    if (!error.empty()) {
      worker_error_ =
          fmt::format("{} {}/{} failed: {}", c.kind == CMD_TRIGGER ? "triggering" : "configuring",
                      c.module, c.args.front(), error);
      queue.clear();  // the rest of this cycle's sequence would run out of order
    }
  }
}

void Sequencer::process(Cycle& cycle) {
  connect();
  std::string mode = params_.frame_mode;
  if (!schedule_.empty()) {
    std::uint64_t period = 0;
    for (const auto& [m, n] : schedule_) period += n;
    auto at = (cycle.index() - 1) % period;
    for (const auto& [m, n] : schedule_) {
      if (at < n) {
        mode = m;
        break;
      }
      at -= n;
    }
  }
  std::lock_guard lock(mutex_);
  if (!worker_error_.empty()) {
    const auto e = std::move(worker_error_);
    worker_error_.clear();
    applied_mode_.clear();  // set it again next cycle
    throw std::runtime_error("sequencer: " + e);
  }
  if (busy()) {  // the last cycle's commands are still on their way
    if (sequences_ == 1) {
      // The first commands wait until DDS has found the modules: expected, and said once.
      if (!first_sequence_told_) {
        first_sequence_told_ = true;
        cycle.log().info("first sequence still running (finding its modules): cycles wait for it");
      }
    } else if (++skipped_ == 1 || skipped_ % 100 == 0) {
      cycle.log().warn(
          "previous sequence still running: cycle skipped ({} so far; its modules took longer "
          "than a cycle to answer)",
          skipped_);
    }
    return;
  }
  ++sequences_;
  timeout_ = std::chrono::duration_cast<std::chrono::milliseconds>(params_.timeout);
  const auto lane = [&](const std::string& module) -> std::deque<Command>& {
    auto [it, added] = lanes_.try_emplace(module);
    if (added) it->second.thread = std::thread([this, module] { worker_loop(module); });
    return it->second.queue;
  };
  if (!mode.empty() && mode != applied_mode_) {
    cycle.log().info("frame mode -> {}", mode);
    for (const auto& [module, kernel] : grabbers_) {
      lane(module).push_back({module, CMD_SET_PARAM, {kernel, "frame_mode", mode}});
    }
    applied_mode_ = mode;
  }
  for (const auto& [module, kernel] : steps_)
    lane(module).push_back({module, CMD_TRIGGER, {kernel}});
  wake_.notify_all();
}

// Stub: no commands (a sequencer without the system it drives has nothing plausible to send).
void Sequencer::stub(Cycle&) {}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::Sequencer, "sequencer")
