#pragma once
// What an applet's code sees of the threaded Runtime (seed 000 §4.4.1, §4.5.3, §4.6.2).

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {

/// Thrown by AppletContext::use in a fail-stop applet when the bundle is not granted (§4.6.2).
class ResourceRevoked : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One negotiation round as an applet defines it (seed §4.5.3): its answer (minimum and maximum
/// time still needed, vote), code to run first, and the follow-up round for the scheduler's
/// acceptance and for its rejection (each a full round again).
struct NegotiationRound {
  Negotiation answer;
  std::function<void()> first;
  std::shared_ptr<NegotiationRound> on_accept;
  std::shared_ptr<NegotiationRound> on_reject;
};

/// What an applet's code sees: its bundles and the scheduler's calls, by bundle name. The
/// threaded Runtime gives its applets a RuntimeContext (runtime_context.hpp); an applet in
/// another process gets one whose calls go to the coordinator over DDS (docs/coordinator.md).
/// The same applet code runs on either.
class AppletContext {
 public:
  virtual ~AppletContext() = default;

  /// @throws std::invalid_argument on an unknown bundle or a refused request.
  virtual void request(const std::string& bundle) = 0;
  virtual void release(const std::string& bundle) = 0;
  virtual void yield(const std::string& bundle) = 0;
  /// Raises the bundle above its level for one plan (seed §4.5.2).
  /// @throws std::invalid_argument from an interrupt handler for a revocation notice
  /// (kRevokeRequested, kNegotiationAccepted/Rejected, kRevokedByForce) or a negotiation round:
  /// an applet never re-prioritises in reaction to a revocation (seed footnote 11).
  virtual void trigger(const std::string& bundle) = 0;
  /// Changes the bundle's priority. @throws std::invalid_argument as trigger() does.
  virtual void set_priority(const std::string& bundle, int priority) = 0;
  virtual void set_deadline(const std::string& bundle, std::optional<Deadline> deadline) = 0;
  /// Answers a revocation with one round's answer only (no code, no follow-up).
  virtual Notification negotiate(const std::string& bundle, const Negotiation& answer) = 0;
  /// Starts a chain of negotiation rounds over a bundle being revoked (seed §4.5.3). This round
  /// runs now: its `first`, then its answer. Each follow-up (for the reply) runs at a later
  /// main-loop step, between steps like the interrupt handlers (Abb. 4.12), one round per step.
  /// The chain ends when a round has no follow-up, after `negotiation_rounds_max` rounds, when
  /// a round takes longer than `negotiation_round_max` (its code, or the wait until its follow-up
  /// starts), or when the bundle is no longer being revoked; then the bundle is yielded (the
  /// defined behaviour has run, so the resource is taken). Call it from the interrupt handler
  /// for kRevokeRequested. A bundle hears from the reassigner of each of its services; while a
  /// chain runs for it, further calls start nothing and return nothing.
  /// Returns the scheduler's reply to this round, if it was answered.
  virtual std::optional<Notification> negotiate(const std::string& bundle,
                                                const NegotiationRound& round) = 0;
  /// Whether a chain of negotiation rounds is under way for the bundle.
  virtual bool negotiating(const std::string& bundle) const = 0;
  /// Whether the bundle is being revoked (revoke requested, not yet yielded or forced).
  virtual bool being_revoked(const std::string& bundle) const = 0;
  /// Runs `body` while the bundle is granted. If it is not, blocks until it is granted again, or
  /// throws ResourceRevoked in a fail-stop applet. Returns false if the applet stops meanwhile.
  virtual bool use(const std::string& bundle, const std::function<void()>& body) = 0;
  /// Whether the bundle may be used now.
  virtual bool granted(const std::string& bundle) const = 0;
  virtual AppletId id() const = 0;
};

}  // namespace oscar::applets
