#include "oscar/applets/runtime.hpp"

#include <algorithm>

namespace oscar::applets {
Runtime::Runtime(Model model, SchedulerOptions options)
    : scheduler_(std::move(model), options), start_(Clock::now()) {
  for (std::size_t a = 0; a < scheduler_.model().applets().size(); ++a) {
    slots_.push_back(std::make_unique<Slot>());
  }
  waiting_since_.assign(scheduler_.model().bundles().size(), {});
  granted_at_.assign(scheduler_.model().bundles().size(), {});
}

Runtime::~Runtime() { stop(); }

milliseconds Runtime::clock() const {
  return std::chrono::duration_cast<milliseconds>(Clock::now() - start_);
}

void Runtime::set_code(const std::string& applet, AppletCode code) {
  std::lock_guard lock(mutex_);
  const AppletId id = scheduler_.model().applet_id(applet);
  if (running_) throw std::invalid_argument("applet '" + applet + "': set code before start()");
  if (!code.step) throw std::invalid_argument("applet '" + applet + "': code needs a step");
  slots_[id]->code = std::move(code);
  slots_[id]->has_code = true;
}

void Runtime::start() {
  std::lock_guard lock(mutex_);
  if (running_) return;
  running_ = true;
  stopping_ = false;
  for (AppletId a = 0; a < slots_.size(); ++a) {
    if (slots_[a]->has_code) slots_[a]->thread = std::thread([this, a] { applet_main(a); });
  }
  reassigner_ = std::thread([this] { reassigner_main(); });
}

void Runtime::stop() {
  {
    std::lock_guard lock(mutex_);
    if (!running_) return;
    stopping_ = true;
  }
  changed_.notify_all();
  for (auto& s : slots_) {
    {
      std::lock_guard lock(mutex_);  // no lost wake-up between a check and a wait
      s->cv.notify_all();
    }
    if (s->thread.joinable()) s->thread.join();
  }
  if (reassigner_.joinable()) reassigner_.join();
  std::lock_guard lock(mutex_);
  running_ = false;
}

void Runtime::pause(const std::string& applet, bool paused) {
  std::lock_guard lock(mutex_);
  slots_[scheduler_.model().applet_id(applet)]->paused = paused;
  slots_[scheduler_.model().applet_id(applet)]->cv.notify_all();
}

bool Runtime::crashed(const std::string& applet) const {
  std::lock_guard lock(mutex_);
  return slots_[scheduler_.model().applet_id(applet)]->crashed;
}

void Runtime::with_scheduler(const std::function<void(Scheduler&)>& f) {
  std::unique_lock lock(mutex_);
  locked_call(f);
}

void Runtime::locked_call(const std::function<void(Scheduler&)>& f) {
  scheduler_.advance_to(std::max(scheduler_.now(), clock()));
  f(scheduler_);
  deliver();
  changed_.notify_all();
}

void Runtime::deliver() {
  for (Notification& n : scheduler_.take_notifications()) {
    if (n.kind == Notification::Kind::kGranted) {
      ++stats_.grants;
      granted_at_[n.bundle] = Clock::now();
    }
    if (n.kind == Notification::Kind::kRevokedByForce) waiting_since_[n.bundle] = Clock::now();
    Slot& slot = *slots_[n.applet];
    slot.interrupts.push_back(std::move(n));
    slot.cv.notify_all();
  }
}

RuntimeStats Runtime::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

// The applet wrapper (seed §4.6.2 "Fail-Stop"): whatever the code throws ends this applet only;
// its bundles are released and everything else goes on.
void Runtime::applet_main(AppletId id) {
  Slot& slot = *slots_[id];
  AppletContext ctx(*this, id);
  try {
    if (slot.code.init) slot.code.init(ctx);  // Abb. 4.12 lines 1–3
    auto next = Clock::now();
    for (;;) {
      std::deque<Notification> queue;
      {
        std::unique_lock lock(mutex_);
        if (stopping_) return;
        queue.swap(slot.interrupts);
      }
      for (const Notification& n : queue) {  // Abb. 4.12 line 4: interrupt handlers first
        if (slot.code.on_interrupt) {
          slot.code.on_interrupt(ctx, n);
        } else if (n.kind == Notification::Kind::kRevokeRequested) {
          ctx.yield(scheduler_.model().bundle(n.bundle).name);
        }
      }
      bool paused;
      {
        std::lock_guard lock(mutex_);
        paused = slot.paused;
      }
      if (!paused) slot.code.step(ctx);  // line 5
      next += slot.code.period;          // lines 6–7
      std::unique_lock lock(mutex_);
      slot.cv.wait_until(lock, next, [&] { return stopping_; });
      if (stopping_) return;
    }
  } catch (const std::exception&) {
    std::lock_guard lock(mutex_);
    slot.crashed = true;
    stats_.crashed.push_back(scheduler_.model().applet(id).name);
    locked_call([id](Scheduler& s) { s.crash(id); });
  }
}

// Revokes by force when a wait limit passes (seed §4.6.1).
void Runtime::reassigner_main() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    milliseconds next = milliseconds::max();
    for (BundleId b = 0; b < scheduler_.model().bundles().size(); ++b) {
      if (auto until = scheduler_.revoke_deadline(b)) next = std::min(next, *until);
    }
    if (next == milliseconds::max()) {
      changed_.wait(lock);
    } else {
      changed_.wait_until(lock, start_ + next);
    }
    if (stopping_) break;
    scheduler_.advance_to(std::max(scheduler_.now(), clock()));
    deliver();
  }
}

}  // namespace oscar::applets
