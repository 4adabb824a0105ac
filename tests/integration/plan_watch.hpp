#pragma once
// The coordinator's plan as a test sees it: the newest AppletPlan on oscar/coordinator/plan, and
// a wait until it shows what the test expects (checked at every new plan).

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>

#include "oscar/coordinator/plan_json.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::test {

class PlanWatch {
 public:
  explicit PlanWatch(DdsParticipant& participant)
      : reader_(participant, topics::applet_plan(), [this](const AppletPlan& p, const auto&) {
          std::lock_guard lock(mutex_);
          plan_ = p;
          changed_.notify_all();
        }) {}

  /// The first plan (the newest, or one that comes within `timeout`) for which `shows` holds.
  std::optional<AppletPlan> wait(const std::function<bool(const AppletPlan&)>& shows,
                                 std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    std::unique_lock lock(mutex_);
    if (changed_.wait_for(lock, timeout, [&] { return plan_ && shows(*plan_); })) return plan_;
    return std::nullopt;
  }
  /// The newest plan as `oscar applets ps --json` prints it, or "none".
  std::string last_json() {
    std::lock_guard lock(mutex_);
    return plan_ ? coordinator::plan_json(*plan_) : "none";
  }

  /// The holders of `service` in `plan` (empty if it has no such service).
  static std::vector<std::string> holders(const AppletPlan& plan, const std::string& service) {
    for (const auto& s : plan.services()) {
      if (s.name() == service) return s.holders();
    }
    return {};
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<AppletPlan> plan_;
  TopicReader<AppletPlan, AppletPlanPubSubType> reader_;  // last: no callback after the rest
};

}  // namespace oscar::test
