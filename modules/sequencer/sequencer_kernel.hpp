#pragma once

#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <oscar/config.h>
#include <oscar/kernel.hpp>

namespace oscar {
class ConfigClient;
class DdsParticipant;
}  // namespace oscar

namespace oscar::modules {

/// A sequencing coordinator for now (seed 004 §4.2, CobraControl): each cycle it triggers the
/// listed single-step kernels in order and, by configuration, sets the framegrabbers' frame
/// mode. It configures with the coordinator's authority (oscar::ConfigClient, sender
/// "coordinator") on the domain and network of the module it runs in.
class Sequencer final : public Kernel {
 public:
  struct Params {
    std::string steps;                ///< "module:kernel,..." triggered in this order each cycle
    std::string framegrabbers;        ///< "module:kernel,..." whose frame_mode it sets
    std::string frame_mode;           ///< "" (leave), full, half or quarter
    std::string frame_mode_schedule;  ///< "quarter:20,half:20": modes by cycles, repeating
    std::chrono::nanoseconds timeout{std::chrono::seconds(2)};
    void describe(ParamSpec& spec);
  };
  explicit Sequencer(KernelSetup& setup);
  ~Sequencer() override;
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  void on_activate() override;
  void on_deactivate() override;
  void on_params_changed() override;
  /// True when no command of an earlier cycle is still on its way (a cycle that finds one
  /// pending is skipped).
  bool idle();

 private:
  using Target = std::pair<std::string, std::string>;  // module, kernel
  void connect();
  void worker_loop(const std::string& module);
  bool busy() const;  // with mutex_ held

  Params params_;
  std::vector<Target> steps_, grabbers_;
  std::vector<std::pair<std::string, std::uint64_t>> schedule_;
  std::string applied_mode_;
  std::unique_ptr<DdsParticipant> participant_;
  std::unique_ptr<ConfigClient> client_;
  // Commands go out from worker threads, one per target module, each module's in order: a kernel
  // of this very module can only take a set_param between kernel calls, and a trigger for it is
  // answered by the module's configuration thread, so process() must not wait for replies; and
  // a remote module's trigger must not hold up the local one (both cameras start together).
  struct Command {
    std::string module;
    CommandKind kind;
    std::vector<std::string> args;
  };
  struct Lane {
    std::thread thread;
    std::deque<Command> queue;
  };
  std::map<std::string, Lane> lanes_;  // by module
  std::mutex mutex_;
  std::condition_variable wake_;
  std::chrono::milliseconds timeout_{2000};
  std::string worker_error_;
  std::uint64_t sequences_ = 0;  // started since activation
  std::uint64_t skipped_ = 0;    // cycles skipped after the first sequence
  bool first_sequence_told_ = false;
  bool stop_ = false;
};

}  // namespace oscar::modules
