#include "oscar/applets/runtime_context.hpp"

#include <algorithm>

#include "oscar/applets/runtime.hpp"

namespace oscar::applets {
namespace {
double ms_between(std::chrono::steady_clock::time_point a,
                  std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}
}  // namespace

BundleId RuntimeContext::bundle_id(const std::string& bundle) const {
  std::lock_guard lock(runtime_.mutex_);  // the model grows while applets run
  return runtime_.scheduler_.model().bundle_id(applet_, bundle);
}

void RuntimeContext::request(const std::string& bundle) {
  const BundleId b = bundle_id(bundle);
  runtime_.with_scheduler([&](Scheduler& s) {
    if (!s.requested(b)) runtime_.waiting_since_[b] = Runtime::Clock::now();
    s.request(b);
  });
}
void RuntimeContext::release(const std::string& bundle) {
  const BundleId b = bundle_id(bundle);
  runtime_.with_scheduler([&](Scheduler& s) { s.release(b); });
}
void RuntimeContext::yield(const std::string& bundle) {
  const BundleId b = bundle_id(bundle);
  runtime_.with_scheduler([&](Scheduler& s) {
    if (s.revoke_deadline(b)) runtime_.waiting_since_[b] = Runtime::Clock::now();
    s.yield(b);
  });
}
void RuntimeContext::refuse_reprioritising(const std::string& bundle, const char* what) const {
  const auto& revoked = runtime_.slot_of(applet_).reacting_to_revocation;
  if (!revoked) return;
  std::lock_guard lock(runtime_.mutex_);
  const Model& m = runtime_.scheduler_.model();
  throw std::invalid_argument(
      "applet '" + m.applet(applet_).name + "' " + what + " bundle '" + bundle +
      "' while it reacts to the revocation of its bundle '" + m.bundle(*revoked).name +
      "'; an applet never re-prioritises in reaction to a revocation (seed 000 §4.5.2, footnote "
      "11: it would make the plan oscillate) — yield or negotiate instead");
}
void RuntimeContext::trigger(const std::string& bundle) {
  const BundleId b = bundle_id(bundle);
  refuse_reprioritising(bundle, "triggers");
  runtime_.with_scheduler([&](Scheduler& s) { s.trigger(b); });
}
void RuntimeContext::set_priority(const std::string& bundle, int priority) {
  const BundleId b = bundle_id(bundle);
  refuse_reprioritising(bundle, "changes the priority of");
  runtime_.with_scheduler([&](Scheduler& s) { s.set_priority(b, priority); });
}
void RuntimeContext::set_deadline(const std::string& bundle, std::optional<Deadline> deadline) {
  const BundleId b = bundle_id(bundle);
  runtime_.with_scheduler([&](Scheduler& s) { s.set_deadline(b, deadline); });
}
Notification RuntimeContext::negotiate(const std::string& bundle, const Negotiation& answer) {
  const BundleId b = bundle_id(bundle);
  Notification n;
  runtime_.with_scheduler([&](Scheduler& s) { n = s.negotiate(b, answer); });
  return n;
}

std::optional<Notification> RuntimeContext::negotiate(const std::string& bundle,
                                                      const NegotiationRound& round) {
  const BundleId b = bundle_id(bundle);
  if (runtime_.slot_of(applet_).negotiations.count(b) != 0) return std::nullopt;
  return runtime_.run_round(*this, b, round);
}

bool RuntimeContext::negotiating(const std::string& bundle) const {
  const BundleId b = bundle_id(bundle);
  return runtime_.slot_of(applet_).negotiations.count(b) != 0;
}

bool RuntimeContext::being_revoked(const std::string& bundle) const {
  const BundleId b = bundle_id(bundle);
  std::lock_guard lock(runtime_.mutex_);
  return runtime_.scheduler_.revoke_deadline(b).has_value();
}

bool RuntimeContext::granted(const std::string& bundle) const {
  const BundleId b = bundle_id(bundle);
  std::lock_guard lock(runtime_.mutex_);
  return runtime_.scheduler_.active(b);
}

bool RuntimeContext::use(const std::string& bundle, const std::function<void()>& body) {
  const BundleId b = bundle_id(bundle);
  {
    std::unique_lock lock(runtime_.mutex_);
    if (!runtime_.scheduler_.active(b)) {
      if (runtime_.scheduler_.model().applet(applet_).fail_stop) {
        throw ResourceRevoked("applet '" + runtime_.scheduler_.model().applet(applet_).name +
                              "' used bundle '" + bundle + "' which is not granted (fail-stop)");
      }
      const auto asked = Runtime::Clock::now();
      auto& slot = *runtime_.slots_[applet_];
      slot.cv.wait(lock, [&] {
        return runtime_.stopping_ || slot.removed || runtime_.scheduler_.active(b);
      });
      if (runtime_.stopping_ || slot.removed) return false;
      const auto now = Runtime::Clock::now();
      // Scheduling overhead: from the grant (or the ask, if later) to running again.
      runtime_.stats_.overhead_ms.push_back(
          ms_between(std::max(asked, runtime_.granted_at_[b]), now));
    }
    if (runtime_.waiting_since_[b] != Runtime::Clock::time_point{}) {
      runtime_.stats_.wait_ms.push_back(
          ms_between(runtime_.waiting_since_[b], Runtime::Clock::now()));
      runtime_.waiting_since_[b] = {};
    }
  }
  // The body runs without the lock: the seed revokes only between steps (or by force after the
  // wait limit, which the next use() then notices).
  body();
  return true;
}

}  // namespace oscar::applets
