#pragma once
// Scenario files: an applet system plus a timeline of events, run on the deterministic Scheduler
// with a logical clock, so every run prints exactly the same (oscar applets run).

#include <optional>
#include <string>
#include <vector>

#include "oscar/applets/config.hpp"

namespace oscar::applets {

/// One event of the timeline.
struct Action {
  enum class Kind {
    kRequest,
    kRelease,
    kYield,
    kTrigger,
    kSetPriority,
    kSetDeadline,
    kCrash,
    kAdvance,
    kNegotiate
  };
  Kind kind = Kind::kRequest;
  BundleId bundle = 0;
  AppletId applet = 0;
  int priority = 0;
  std::optional<Deadline> deadline;
  milliseconds advance{0};
  Negotiation negotiation;
  bool trigger = false;  ///< kRequest: trigger right after requesting.
  std::string where;     ///< file:line for messages.
};

/// A step: actions at one time, then the holders are printed (and checked against `expect`).
struct Step {
  std::string label;
  std::optional<milliseconds> t;
  std::vector<Action> actions;
  std::vector<std::pair<std::string, std::string>> expect;         ///< service, holder
  std::vector<std::pair<std::string, std::string>> expect_active;  ///< service, active holder
  std::string where;
};

/// The state after one step.
struct StepResult {
  std::string label;
  milliseconds t{0};
  std::vector<std::pair<std::string, std::string>> holders;  ///< In service declaration order.
  std::vector<std::pair<std::string, std::string>> active;   ///< Scheduler::active_holder.
  std::vector<std::string> notes;                            ///< Notifications, for people.
  std::vector<std::string> mismatches;                       ///< Failed expectations.
};

/// A system and its timeline.
class Scenario {
 public:
  /// @throws std::invalid_argument "file:line: ..." on bad input (see docs/applets.md).
  static Scenario load_file(const std::string& path);
  /// @throws std::invalid_argument "file:line: ..." on bad input.
  static Scenario parse(const std::string& yaml_text, const std::string& file);

  /// Runs the timeline on a fresh Scheduler. Deterministic: the same file gives the same result.
  /// @throws std::invalid_argument "file:line: ..." if an event is refused (e.g. bad deadline).
  /// If `final_state` is given, the scheduler after the last step is moved into it.
  std::vector<StepResult> run(Scheduler* final_state = nullptr) const;

  const SystemConfig& system() const { return system_; }
  const std::vector<Step>& steps() const { return steps_; }
  /// runner.auto_yield: whether applets yield a bundle at once when its revocation is requested.
  bool auto_yield() const { return auto_yield_; }

 private:
  SystemConfig system_;
  std::vector<Step> steps_;
  bool auto_yield_ = true;  ///< runner.auto_yield: applets yield a revoked bundle at once.
};

/// A table for people: one line per step, one column per service.
std::string format_text(const std::vector<StepResult>& results);
/// {"steps":[{"event":..,"t_ms":..,"holders":{..},"notes":[..],"mismatches":[..]}]}
std::string format_json(const std::vector<StepResult>& results);

}  // namespace oscar::applets
