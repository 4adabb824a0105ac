#pragma once
// The deterministic scheduler core (seed 000 §4.1–4.6): requests, priorities, deadlines and
// triggering drive the plan; per-service reassigners (inform, negotiate, wait, revoke by force,
// grant, notify continuation) run on a logical clock. No threads: the threaded Runtime and the
// scenario runner both drive this class.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "oscar/applets/model.hpp"
#include "oscar/applets/plan.hpp"

namespace oscar::applets {

using std::chrono::milliseconds;

/// Tunables of the scheduler; defaults follow the seed.
struct SchedulerOptions {
  milliseconds context_switch{0};  ///< c in the footnote to eq. 4.9–4.10.
  milliseconds revoke_wait{5000};  ///< Wait for a release before revoking by force.
  /// Longest a negotiation round may take and the most time one round may grant (seed §4.5.3).
  milliseconds negotiation_round_max{20000};
  int negotiation_rounds_max = 3;  ///< Rounds per reassigner and holder (the scheduler decides).
};

/// An applet's answer to a revocation (seed §4.5.3, "Verhandlungsrunden").
struct Negotiation {
  milliseconds min_needed{0};  ///< Least time the applet still needs the bundle.
  milliseconds max_needed{0};  ///< Most time it needs.
  /// Vote: true agrees to the revocation after the time it needs (granted max_needed if that
  /// fits, else min_needed); false objects to it (upheld with max_needed if that fits, else
  /// rejected). Either way within the round limits and new holders' deadlines.
  bool accept = false;
};

/// What the scheduler tells an applet; delivered through the applet's interrupt queue.
struct Notification {
  enum class Kind {
    kGranted,              ///< The bundle may be used (again).
    kRevokeRequested,      ///< The plan gives `service` to others: finish, yield or negotiate.
    kNegotiationAccepted,  ///< More time granted, until `until`.
    kNegotiationRejected,  ///< No more time; yield before `until`.
    kRevokedByForce,       ///< The wait limit passed: the bundle is gone.
    kDeadlineOverlap,      ///< Its deadline overlaps `other`'s (eq. 4.11); best effort.
    /// t_finish (`until`) passed: the access window is over, the request is withdrawn (a bundle
    /// still in use is given back through its reassigners like any other).
    kDeadlineExpired,
  };
  Kind kind = Kind::kGranted;
  AppletId applet = 0;
  BundleId bundle = 0;
  std::vector<AppletId> new_holders;  ///< Who gets `service` (kRevokeRequested).
  std::optional<BundleId> other;      ///< kDeadlineOverlap.
  milliseconds until{0};              ///< Revocation, negotiation: the time by which to yield.
  /// The service whose reassigner speaks (revocation, negotiation, force); none otherwise.
  std::optional<ServiceId> service;
};

/// The state of one service's reassigner (seed §4.4.1, Abb. 4.13–4.14): it runs while bundles
/// still hold the service that the plan gives to others (or to nobody). Each such holder has
/// its own wait limit and negotiation rounds with this reassigner.
struct Reassignment {
  struct Giving {
    BundleId bundle = 0;
    milliseconds until{0};  ///< Revoked by force at this time unless yielded before.
    int rounds = 0;         ///< Negotiation rounds so far.
  };
  std::vector<Giving> giving;  ///< Holders still giving the service back; empty: not running.
  std::vector<AppletId> to;    ///< Applets the plan gives the service to next (sorted).
};

/// Pure scheduler: call its methods from one thread (the Runtime serialises them).
class Scheduler {
 public:
  /// @throws std::invalid_argument if a bundle's initial priority is negative.
  explicit Scheduler(Model model, SchedulerOptions options = {});

  const Model& model() const { return model_; }
  const SchedulerOptions& options() const { return options_; }
  milliseconds now() const { return now_; }

  /// Moves the logical clock forward. What falls due on the way happens at its own time, in
  /// order: requests whose t_finish passed expire (kDeadlineExpired), requests whose t_early is
  /// reached are planned (a new plan), wait limits that passed revoke by force.
  /// @throws std::invalid_argument if `t` lies before now().
  void advance_to(milliseconds t);

  /// Asks for a bundle (again). A bundle with a configured deadline (Bundle::request_deadline)
  /// gets it counted from now, replacing one set before.
  /// @throws std::invalid_argument if another requested bundle of the
  /// same applet uses one of its services and either asks for exclusive access, or if the
  /// applet crashed.
  void request(BundleId bundle);
  /// Gives a bundle back and withdraws the request.
  void release(BundleId bundle);
  /// Hands a bundle back after a revocation but keeps the request (it is granted again later).
  void yield(BundleId bundle);
  /// Changes a bundle's priority. @throws std::invalid_argument if negative.
  void set_priority(BundleId bundle, int priority);
  /// Sets or clears a deadline (eq. 4.9–4.10 with the context-switch time). The bundle is not
  /// granted before t_early, and its request expires at t_finish (seed §4.5.1).
  /// @throws std::invalid_argument naming the violated inequality.
  void set_deadline(BundleId bundle, std::optional<Deadline> deadline);
  /// Raises a requested bundle just above its priority level for one plan, then restores it
  /// (seed §4.5.2, Abb. 4.18). @throws std::invalid_argument if the bundle is not requested.
  void trigger(BundleId bundle);
  /// An applet crashed (seed §4.6.1): all its bundles are released at once, and the services it
  /// provides become unavailable for good — the bundles using them (directly or down the
  /// hierarchy) lose them at once (kRevokedByForce naming the service) and keep their request,
  /// which cannot be granted while the service is gone. Nothing else is touched.
  void crash(AppletId applet);
  /// A service goes away for a while (false: the modules providing it failed) or comes back
  /// (true). While it is away the bundles using it, directly or down the hierarchy, lose it at
  /// once (kRevokedByForce naming the service) and keep their request; they are granted again
  /// when it is back. A service whose service applet crashed stays unavailable.
  void set_available(ServiceId service, bool available);
  /// Adds services and applets while the scheduler runs (seed 000 §4.1.1: the scheduler is the
  /// registrar of services and applets), all or nothing. Their bundles start unrequested with
  /// their configured priority; the plan is made again. An added applet may provide a service
  /// added with it, or one whose providing applet was removed (it becomes available again), or
  /// any other that no granted bundle uses now.
  /// @throws std::invalid_argument as Model::add, for a negative priority, and for a provided
  ///         service that a granted bundle uses now; nothing is changed then.
  AddedIds add(const ModelAddition& addition);
  /// Removes an applet: its bundles are released as when it ends, the services it provides
  /// become unavailable (as when it crashes) until another applet provides them, and it is
  /// gone from the model (its name may be added again; its ids are never reused).
  /// @throws std::invalid_argument if it was removed already.
  void remove_applet(AppletId applet);
  /// Removes a service nobody uses. @throws std::invalid_argument naming the applets whose
  /// bundles use it, the services that need it, or the applet that provides it.
  void remove_service(ServiceId service);
  /// Whether the applet was removed.
  bool removed(AppletId applet) const { return model_.applet(applet).removed; }
  /// Whether the applet crashed.
  bool crashed(AppletId applet) const { return crashed_.at(applet) != 0; }
  /// Whether the service can be used: false once its service applet crashed.
  bool available(ServiceId service) const { return plan_context_.unavailable.at(service) == 0; }
  /// An applet answers a revocation: every reassigner taking a service of the bundle decides on
  /// its own (it gets one notification per service). Returns the summary: accepted if all
  /// accepted, `until` the earliest time by which the bundle must be yielded.
  /// @throws std::invalid_argument if the bundle is not being revoked.
  Notification negotiate(BundleId bundle, const Negotiation& answer);

  /// The current plan (what the scheduler intends).
  const Plan& plan() const { return plan_; }
  /// Whether a bundle may be used now (granted and handed over).
  bool active(BundleId bundle) const { return active_.at(bundle) != 0; }
  /// Whether the bundle is being revoked and by when it must be yielded (the earliest wait
  /// limit among the reassigners of its services).
  std::optional<milliseconds> revoke_deadline(BundleId bundle) const;
  /// The earliest wait limit of any running reassigner (when advance_to next revokes by force).
  std::optional<milliseconds> next_forced_revocation() const;
  /// The earliest time at which advance_to changes something: a forced revocation, a t_early
  /// reached or a t_finish passed. The threaded Runtime wakes then.
  std::optional<milliseconds> next_event() const;
  /// The reassigner of a service; `giving` is empty when none runs.
  const Reassignment& reassignment(ServiceId service) const { return reassigners_.at(service); }
  bool requested(BundleId bundle) const { return state_.at(bundle).requested; }
  int priority(BundleId bundle) const { return state_.at(bundle).priority; }
  const std::optional<Deadline>& deadline(BundleId bundle) const {
    return state_.at(bundle).deadline;
  }

  /// The planned holder of a service for people: applet names (sorted, joined by ','), "blocked"
  /// (requested but not granted, or held up by a dependency), "unavailable" (its service applet
  /// crashed) or "undef" (nobody asked).
  std::string holder(ServiceId service) const;
  /// Who may use a service right now (handed over, seed Abb. 4.2): applet names joined by ',',
  /// or "none". Differs from holder() while a reassignment is under way.
  std::string active_holder(ServiceId service) const;

  /// Notifications since the last call, in order.
  std::vector<Notification> take_notifications();
  /// Number of plans computed so far.
  std::uint64_t plans_computed() const { return plans_; }
  /// How long the last plan took to compute (wall time of calculate_assignments).
  std::chrono::nanoseconds last_plan_time() const { return last_plan_time_; }

 private:
  /// Eq. 4.9 and 4.10 for `d` as `bundle`'s deadline now. @throws std::invalid_argument.
  void check_deadline(BundleId bundle, const Deadline& d) const;
  /// One use of a service that granting a bundle brings along (its own resources and, down the
  /// hierarchy, the services' own uses). Two bundles clash on a service when they use it through
  /// different users and one of those uses is exclusive (the plan's rule, Abb. 4.21).
  struct FootUse {
    ServiceId service = 0;
    Use::By by = Use::By::kResource;
    std::uint32_t user = 0;  ///< ResourceId or ServiceId, per `by`.
    bool exclusive = false;
  };

  /// A notification of `kind` to the bundle's applet, stamped now.
  Notification notice(Notification::Kind kind, BundleId bundle,
                      std::optional<ServiceId> service = std::nullopt) const;
  void replan();
  // Takes unavailable services from the bundles using them now, then plans again.
  void revoke_unavailable();
  // Expiries, t_early reached and forced revocations due at now_.
  void handle_due();
  void update_handover();
  const std::vector<FootUse>& footprint(BundleId bundle) const;
  const std::vector<ServiceId>& services_of(BundleId bundle) const;
  /// Whether the bundle uses `service` itself: one of its resources or, down the hierarchy, a
  /// configured dependency of those. Not a service applet's resource, which that applet holds.
  /// Its holder hears only from these reassigners (the others track it silently).
  bool uses_itself(BundleId bundle, ServiceId service) const;
  bool conflicts(BundleId a, BundleId b) const;
  void check_bundle(BundleId bundle) const;
  // Throws if the bundle's applet was removed (`what` names the call).
  void check_live(BundleId bundle, const char* what) const;
  // Sizes the per-bundle, per-service and per-applet state to the model, and forgets the
  // cached footprints (what a service needs may have changed).
  void fit_to_model();
  void start_giving(BundleId bundle);
  void stop_giving(BundleId bundle);
  Notification negotiate_with(ServiceId service, Reassignment::Giving& giving,
                              const Negotiation& answer);

  Model model_;
  SchedulerOptions options_;
  milliseconds now_{0};
  std::vector<BundleState> state_;
  Plan plan_;
  std::vector<char> active_;
  std::vector<char> revoking_;             // per bundle: in some reassigner's `giving`
  std::vector<Reassignment> reassigners_;  // per service
  std::vector<char> crashed_;              // per applet
  std::vector<char> provider_gone_;        // per service: its service applet crashed or left
  PlanContext plan_context_;               // unavailable: per service
  std::vector<Notification> notifications_;
  std::uint64_t plans_ = 0;
  std::chrono::nanoseconds last_plan_time_{0};
  mutable std::vector<std::optional<std::vector<FootUse>>> footprint_cache_;  // sorted by service
  mutable std::vector<std::optional<std::vector<ServiceId>>> services_cache_;
  mutable std::vector<std::optional<std::vector<ServiceId>>> own_cache_;  // sorted
};

}  // namespace oscar::applets
