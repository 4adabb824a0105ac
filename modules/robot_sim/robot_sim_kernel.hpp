#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>

#include <oscar/kernel.hpp>
#include <oscar/swarm_types.hpp>

#include "pilot_trajectory.hpp"

namespace oscar::modules {

/// A simulated disc robot's pilot (the live swarm, docs in README.md): it drives its committed
/// trajectory in real time and publishes its RobotState every cycle; command `propose` takes a
/// transaction's trajectory sections (ACK or NAK), `commit` splices them in and `abort` drops
/// them; `committed` tells what it has committed from now on (for a coordinator that restarted).
/// Faults are injected by parameters: random NAKs, a breakdown, slow acknowledgements.
class RobotSim final : public Kernel {
 public:
  struct Params {
    double radius = 0.25;           ///< m
    double max_speed = 1.0;         ///< m/s
    double turning_radius = 0;      ///< m; 0 = turns on the spot
    double start_x = 0;             ///< m
    double start_y = 0;             ///< m
    double start_heading = 0;       ///< rad
    double nak_probability = 0;     ///< of refusing an otherwise acceptable proposal
    int seed = 1;                   ///< of the random NAKs
    double breakdown_after_s = -1;  ///< after activation; negative = never
    int ack_delay_ms = 0;           ///< the answer to `propose` waits this long
    /// A proposal nobody decided on is dropped once its first section began this long ago.
    std::chrono::nanoseconds undecided_for{std::chrono::seconds(10)};
    void describe(ParamSpec& spec);
  };
  explicit RobotSim(KernelSetup& setup);
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  void on_activate() override;

 private:
  CommandAnswer propose(const Trajectory& request);
  CommandAnswer commit(const TransactionDecision& decision);
  CommandAnswer abort(const TransactionDecision& decision);
  CommandAnswer committed_plan(const CommittedPlanQuery& query);
  std::string refusal(const Trajectory& request, Stamp now) const;
  std::string decision_refusal(const TransactionDecision& decision) const;
  Stamp command_time() const;
  void clock(Stamp now);
  void break_down_if_due(Stamp now);
  void drop_undecided(Cycle& cycle, Stamp now);
  RobotJob job_at(Stamp now) const;  // id empty: none
  RobotState state_at(Stamp now, const Motion& m) const;

  Output<RobotState>& state_;
  Params params_;
  std::string name_;
  PilotTrajectory committed_;
  std::map<std::uint64_t, Trajectory> pending_;  // by transaction
  std::map<std::string, RobotJob> jobs_;         // the committed schedule, by id
  std::mt19937_64 random_;
  std::optional<Stamp> activated_at_;  // the first cycle after activation
  std::optional<Stamp> last_cycle_;
  std::chrono::steady_clock::time_point last_cycle_steady_;
  bool broken_ = false;
  bool fault_logged_ = false;
  std::string fault_;
};

}  // namespace oscar::modules
