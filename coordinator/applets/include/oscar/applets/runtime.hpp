#pragma once
// The threaded runtime (seed 000 §4.4, §4.6.2): every applet in its own thread inside a wrapper
// that contains crashes; interrupt handlers queued to the applet and run between its main-loop
// steps (Abb. 4.12), with negotiation rounds spread over the steps (§4.5.3); a thread that moves
// the scheduler's clock at its next event (a wait limit passed: revoke by force; a t_early
// reached or a t_finish passed: plan again). The decisions are the deterministic Scheduler's,
// driven by the steady clock.

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "oscar/applets/applet_context.hpp"
#include "oscar/applets/scheduler.hpp"

namespace oscar::applets {

/// The code of one applet (Abb. 4.12): init once, then step every period; `on_interrupt` runs
/// queued notifications between steps. By default a revoked bundle is yielded at once.
struct AppletCode {
  std::function<void(AppletContext&)> init;
  std::function<void(AppletContext&)> step;
  std::function<void(AppletContext&, const Notification&)> on_interrupt;
  std::chrono::milliseconds period{10};
};

/// Measured figures of a run.
struct RuntimeStats {
  std::uint64_t grants = 0;          ///< Bundles handed to an applet (re)assignments.
  std::vector<double> wait_ms;       ///< Request (or revocation) to the first use again.
  std::vector<double> overhead_ms;   ///< Grant to the waiting applet running: scheduling cost.
  std::vector<std::string> crashed;  ///< Applets whose code threw.
};

/// How an applet added at run time runs (Runtime::add): its code in a thread of its own here,
/// or elsewhere with its notifications handed to `forward` (as Runtime::set_remote), or neither
/// (it is driven through with_scheduler only).
struct AppletRunner {
  std::optional<AppletCode> code;
  std::function<void(const Notification&)> forward;
};

/// Runs applets in threads around one Scheduler. Construct, add code, start, stop; services and
/// applets may be added and removed while it runs.
class Runtime {
 public:
  explicit Runtime(Model model, SchedulerOptions options = {});
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  /// Sets the code of a configured applet. @throws std::invalid_argument if unknown or started.
  void set_code(const std::string& applet, AppletCode code);
  /// The applet's code runs elsewhere (another process, docs/coordinator.md): it gets no thread
  /// here, and each of its notifications is handed to `forward`, in order, under the runtime's
  /// lock — so `forward` only queues; it must not call back into the runtime.
  /// @throws std::invalid_argument if unknown, started, or the applet has code.
  void set_remote(const std::string& applet, std::function<void(const Notification&)> forward);
  /// Starts one thread per applet with code, and the reassigner.
  void start();
  /// Stops and joins all threads (also called by the destructor).
  void stop();
  /// Pauses an applet between steps; a paused applet releases nothing by itself.
  void pause(const std::string& applet, bool paused);
  /// Whether an applet's thread ended by an exception (its bundles were released).
  bool crashed(const std::string& applet) const;

  /// Adds services and applets (Scheduler::add), all or nothing; `runners` says how each added
  /// applet runs (by name; an applet without one runs nowhere). Applets with code start at once
  /// if the runtime runs.
  /// @throws std::invalid_argument as Scheduler::add, or for a runner naming no added applet,
  ///         without code and forward, or with both; nothing is changed then.
  AddedIds add(const ModelAddition& addition, std::map<std::string, AppletRunner> runners = {});
  /// Removes an applet (Scheduler::remove_applet) and ends its thread: it is told nothing more,
  /// a use() it waits in returns false, and this returns once its step ended.
  /// @throws std::invalid_argument for an unknown applet, or when called from its own thread.
  void remove_applet(const std::string& applet);
  /// Removes a service (Scheduler::remove_service).
  /// @throws std::invalid_argument for an unknown service, or naming what uses it.
  void remove_service(const std::string& service);

  /// A bundle's name, read under the runtime's lock (the model changes while applets run).
  std::string bundle_name(BundleId bundle) const;

  /// Calls `f` with the scheduler under the runtime's lock, then delivers notifications.
  void with_scheduler(const std::function<void(Scheduler&)>& f);
  RuntimeStats stats() const;

 private:
  friend class RuntimeContext;
  struct Slot {
    AppletCode code;
    std::deque<Notification> interrupts;
    bool paused = false;
    bool crashed = false;
    bool has_code = false;
    bool removed = false;                              // removed at run time: its thread ends
    std::function<void(const Notification&)> forward;  // set: the applet runs elsewhere
    /// A chain of negotiation rounds under way (seed §4.5.3). Applet thread only.
    struct Chain {
      std::shared_ptr<const NegotiationRound> next;  ///< The follow-up to run.
      std::chrono::steady_clock::time_point round_started;
      std::uint64_t step = 0;  ///< Main-loop step in which the last round ran.
      int rounds = 0;
    };
    std::map<BundleId, Chain> negotiations;  // applet thread only
    /// The bundle whose revocation the applet's code is reacting to (an interrupt handler for a
    /// revocation notice, or a negotiation round), if any: no re-prioritising meanwhile (seed
    /// §4.5.2, footnote 11). Applet thread only.
    std::optional<BundleId> reacting_to_revocation;
    std::uint64_t steps = 0;     // main-loop steps so far; applet thread only
    std::condition_variable cv;  // wakes this applet only (no thundering herd)
    std::thread thread;
  };
  using Clock = std::chrono::steady_clock;

  milliseconds clock() const;
  void locked_call(const std::function<void(Scheduler&)>& f);  // lock held by caller
  void deliver();                                              // lock held
  // Unlocks, then wakes the applets deliver() queued notifications for: a woken applet does
  // not block on the mutex its waker still holds.
  void wake(std::unique_lock<std::mutex>& lock);
  void applet_main(AppletId id, Slot& slot);
  // The slot of an applet, found under the lock (slots_ grows while applets run); the slot
  // itself lives as long as the runtime. Not with the lock held.
  Slot& slot_of(AppletId id) const;

  // Runs one negotiation round for `bundle` and keeps or ends its chain (applet thread).
  std::optional<Notification> run_round(AppletContext& ctx, BundleId bundle,
                                        const NegotiationRound& round);
  // Runs the follow-up rounds due in this main-loop step (applet thread).
  void run_negotiations(AppletContext& ctx);
  void reassigner_main();

  mutable std::mutex mutex_;
  std::condition_variable changed_;                // wakes the clock thread
  milliseconds forcing_at_ = milliseconds::max();  // the event the clock thread waits for
  std::vector<Slot*> to_wake_;
  Scheduler scheduler_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<Clock::time_point> waiting_since_;  // per bundle: asked, not yet granted
  std::vector<Clock::time_point> granted_at_;     // per bundle
  RuntimeStats stats_;
  Clock::time_point start_;
  bool running_ = false;
  bool stopping_ = false;
  std::thread reassigner_;
};

}  // namespace oscar::applets
