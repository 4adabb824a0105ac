#pragma once
/// @file Module: the frame of one module process (seed 004 §2.2, "Rahmen"). It hosts one or more
/// kernels, does all communication (DDS and in-process handoff), runs the kernels in one
/// processing thread according to their modes, and obeys configuration commands.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <oscar/config.h>

#include "oscar/kernel_instance.hpp"
#include "oscar/module_spec.hpp"

namespace oscar {

class DdsParticipant;
namespace internal {
class DdsLogSink;
class SequenceStore;
}  // namespace internal

/// Where a configuration command came from as the transport saw it, whatever it says about its
/// sender: the modules of the running system that live in the process that wrote it.
struct CommandOrigin {
  /// Empty for a process that hosts no module of the system: boot, the registry, a tool.
  std::vector<std::string> modules;
  /// In a secured system, the identity the writer authenticated as ("registry", "boot",
  /// "operator_boot", "module.coordinator"; "" for any other): it, not the command's claimed
  /// sender, decides. Unset without DDS Security.
  std::optional<std::string> identity{};
};

class Module {
 public:
  /// Loads the kernel types, constructs the kernels, checks the multi-core rules and wires the
  /// kernels of this module to each other. Acquires no DDS or threads.
  /// @throws std::invalid_argument / std::runtime_error naming the module, kernel and rule.
  explicit Module(ModuleSpec spec, const std::vector<std::string>& plugin_path);
  ~Module();
  Module(const Module&) = delete;
  Module& operator=(const Module&) = delete;

  /// Joins the DDS domain (or stays in-process if domain < 0), wires remote inputs, starts the
  /// processing thread and applies the initial modes.
  void start(int domain);
  /// Blocks until a shutdown command or request_stop().
  void wait();
  void request_stop();
  /// Stops threads and leaves the domain (also done by the destructor).
  void stop();

  /// Applies a configuration command (as one arriving on oscar/config/<module> would be) if its
  /// sender may give it: only the coordinator configures (the registry suspends, resumes and
  /// re-applies; boot applies the initial configuration), and a command from the process of a
  /// module other than the coordinator is refused whatever name it claims.
  ConfigReply apply(const ConfigCommand& command, const CommandOrigin& origin = {});
  ModuleState state() const;
  /// True while one kernel call has run longer than the watchdog limit (the heartbeat stops).
  bool hung() const;
  /// Why the module asked to be stopped on its own (on_kernel_error: restart, its RouDi gone);
  /// empty otherwise.
  std::string exit_reason() const;

  const ModuleSpec& spec() const { return spec_; }
  KernelInstance& kernel(const std::string& name);

 private:
  struct Slot;
  class Dds;

  void check_multicore_rules() const;
  void wire_in_process();
  std::string connect(InputPort& input, const std::string& source,
                      std::optional<std::chrono::milliseconds> switch_wait);
  void processing_loop();
  void run_slot(Slot& slot, Trigger trigger, bool stub);
  void kernel_failed(Slot& slot, std::string failure);
  /// Stops the module on its own: oscar-run exits with kKernelFailureExit and the registry
  /// starts it again. Thread-safe; the first reason is kept.
  void end_for_restart(std::string reason);
  void mark_pending(Slot& slot);
  void post_and_wait(const std::function<void()>& task);
  void report(const std::string& transition);
  Slot& slot_for(const std::string& kernel, const std::string& command);
  std::vector<Slot*> slots_for(const std::string& kernel_or_all, const std::string& command);
  CommandAnswer deliver_command(Slot& slot, const CommandPort& port, const void* request);
  std::string rewire(Slot& slot, const std::string& input, const std::string& source,
                     std::chrono::milliseconds switch_wait);
  ModuleState state_locked() const;

  ModuleSpec spec_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::shared_ptr<spdlog::logger> log_;  // the frame's; each kernel logs as "<module>/<kernel>"
  std::shared_ptr<internal::DdsLogSink> log_sink_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> tasks_;
  bool suspended_ = false;
  bool stopping_ = false;
  bool stop_requested_ = false;
  std::condition_variable stopped_;
  std::string last_transition_;
  std::string exit_reason_;
  std::atomic<std::int64_t> busy_since_ns_{0};  // steady clock; 0 while no kernel runs
  std::thread processing_;
  std::unique_ptr<internal::SequenceStore> sequences_;  // declared before dds_: outlives it
  std::unique_ptr<Dds> dds_;
};

}  // namespace oscar
