#pragma once
// The resource plan: calculateAssignments of seed 000 Abb. 4.19–4.21, as a pure function.

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "oscar/applets/model.hpp"

namespace oscar::applets {

/// Dynamic state of one bundle as the plan sees it.
struct BundleState {
  bool requested = false;
  int priority = kPriorityNormal;
  bool boosted = false;  ///< Triggered: sorts just above its priority level (seed §4.5.2).
  std::optional<Deadline> deadline;
};

/// One granted use of a service and the requested bundle whose grant brought it in.
struct GrantedUse {
  Use use;
  BundleId root = 0;
};

/// Who uses which service: per service its granted uses in grant order, all in one flat list
/// (a list per service cost an allocation per service and plan).
class UsesByService {
 public:
  UsesByService() = default;
  /// From uses in grant order, each with a service below `services`.
  UsesByService(std::size_t services, const std::vector<GrantedUse>& in_grant_order);

  /// The uses of `service`, in grant order.
  std::span<const GrantedUse> operator[](ServiceId service) const {
    return {uses_.data() + begin_[service], begin_[service + 1] - begin_[service]};
  }
  /// As operator[]. @throws std::out_of_range for a service the plan does not know.
  std::span<const GrantedUse> at(ServiceId service) const;
  /// The number of services.
  std::size_t size() const { return begin_.empty() ? 0 : begin_.size() - 1; }
  /// All uses, by service, each service's in grant order.
  const std::vector<GrantedUse>& all() const { return uses_; }

 private:
  std::vector<std::uint32_t> begin_;  // per service and one past the last: its first use
  std::vector<GrantedUse> uses_;
};

/// What a plan needs besides the bundles' state.
struct PlanContext {
  /// The time the plan is made for: a bundle whose deadline's t_early lies after it is not
  /// considered yet (seed §4.5.1: access from the earliest start on); a plan at t_early grants it.
  std::chrono::milliseconds now{0};
  std::chrono::milliseconds context_switch{0};  ///< c of eq. 4.9–4.11.
  /// Per service (or empty: none): the service is gone (its service applet crashed); nothing
  /// that needs it can be granted (seed §4.6.1, cascading effects).
  std::vector<char> unavailable;
};

/// The result of one plan.
struct Plan {
  /// The time it was made for (PlanContext::now).
  std::chrono::milliseconds time{0};
  /// The sorted working set W_t (requested bundles); the next plan starts from it.
  std::vector<BundleId> order;
  std::vector<char> bundle_granted;    ///< Per bundle: all its resources are granted.
  std::vector<char> resource_granted;  ///< Per resource.
  UsesByService uses;                  ///< Per service: who uses it.
  /// Requested bundles of one priority whose deadlines overlap (eq. 4.11), each pair once.
  std::vector<std::pair<BundleId, BundleId>> deadline_overlaps;
  /// Per bundle: the priority it was sorted with (cycles take their highest, seed §4.5.1).
  std::vector<int> effective_priority;
  /// PlanContext::unavailable, kept for can_grant.
  std::vector<char> unavailable;
};

/// Computes the plan (seed Abb. 4.19): the working set `previous_order` extended by new requests,
/// stably sorted by priority (descending; a triggered bundle just above its level), then EDF on
/// the relative deadline, then held bundles first; walked greedily, each bundle granted with
/// everything it needs down the service hierarchy (priority inheritance) or not at all. A
/// requested bundle whose t_early lies after `context.now` keeps its place in the working set
/// but is not granted (it waits, taking nothing from others).
/// Runs in O(n log n) for n bundles when the service hierarchy is bounded.
Plan calculate_assignments(const Model& model, const std::vector<BundleState>& state,
                           const std::vector<BundleId>& previous_order,
                           const std::vector<char>& previously_granted,
                           const PlanContext& context = {});

/// Whether a bundle's request waits for its earliest start: t_early later than `now`.
bool waits_for_t_early(const BundleState& state, std::chrono::milliseconds now);

/// Whether a new use of `service` with `access` could be granted beside `plan` (with all it needs,
/// none of it unavailable).
bool can_grant(const Model& model, const Plan& plan, ServiceId service, Access access);

/// Eq. 4.11 with the context-switch time c: min(t_early) + d_i + d_j + c > max(t_finish).
bool deadlines_overlap(const Deadline& a, const Deadline& b, std::chrono::milliseconds c);

}  // namespace oscar::applets
