#include "oscar/applets/runtime.hpp"

#include <algorithm>

#include "oscar/applets/runtime_context.hpp"

namespace oscar::applets {
namespace {

// Notices about taking a bundle away (seed §4.4.1, §4.5.3, §4.6.1): what an applet must not
// answer with a new priority (footnote 11).
bool is_revocation(Notification::Kind kind) {
  return kind == Notification::Kind::kRevokeRequested ||
         kind == Notification::Kind::kNegotiationAccepted ||
         kind == Notification::Kind::kNegotiationRejected ||
         kind == Notification::Kind::kRevokedByForce;
}

}  // namespace

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
  if (slots_[id]->forward) {
    throw std::invalid_argument("applet '" + applet + "' runs elsewhere: it has no code here");
  }
  slots_[id]->code = std::move(code);
  slots_[id]->has_code = true;
}

void Runtime::set_remote(const std::string& applet,
                         std::function<void(const Notification&)> forward) {
  std::lock_guard lock(mutex_);
  const AppletId id = scheduler_.model().applet_id(applet);
  if (running_)
    throw std::invalid_argument("applet '" + applet + "': set it remote before start()");
  if (slots_[id]->has_code) {
    throw std::invalid_argument("applet '" + applet + "' has code here: it cannot be remote");
  }
  slots_[id]->forward = std::move(forward);
}

void Runtime::start() {
  std::lock_guard lock(mutex_);
  if (running_) return;
  running_ = true;
  stopping_ = false;
  for (AppletId a = 0; a < slots_.size(); ++a) {
    Slot* slot = slots_[a].get();
    if (slot->has_code && !slot->removed) {
      slot->thread = std::thread([this, a, slot] { applet_main(a, *slot); });
    }
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
  std::vector<Slot*> slots;
  {
    std::lock_guard lock(mutex_);  // no lost wake-up between a check and a wait
    for (auto& s : slots_) {
      s->cv.notify_all();
      slots.push_back(s.get());
    }
  }
  for (Slot* s : slots) {
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
  wake(lock);
}

void Runtime::locked_call(const std::function<void(Scheduler&)>& f) {
  scheduler_.advance_to(std::max(scheduler_.now(), clock()));
  f(scheduler_);
  deliver();
  // Wake the clock thread only for an earlier event than it waits for (not on every call).
  const auto next = scheduler_.next_event();
  if (next && *next < forcing_at_) changed_.notify_all();
}

void Runtime::wake(std::unique_lock<std::mutex>& lock) {
  std::vector<Slot*> slots;
  slots.swap(to_wake_);
  lock.unlock();
  for (Slot* slot : slots) slot->cv.notify_all();
}

void Runtime::deliver() {
  for (Notification& n : scheduler_.take_notifications()) {
    if (n.kind == Notification::Kind::kGranted) {
      ++stats_.grants;
      granted_at_[n.bundle] = Clock::now();
    }
    if (n.kind == Notification::Kind::kRevokedByForce) waiting_since_[n.bundle] = Clock::now();
    Slot& slot = *slots_[n.applet];
    if (slot.removed) continue;
    if (slot.forward) {  // its code runs elsewhere
      slot.forward(n);
      continue;
    }
    slot.interrupts.push_back(std::move(n));
    if (std::find(to_wake_.begin(), to_wake_.end(), &slot) == to_wake_.end()) {
      to_wake_.push_back(&slot);
    }
  }
}

Runtime::Slot& Runtime::slot_of(AppletId id) const {
  std::lock_guard lock(mutex_);
  return *slots_.at(id);
}

std::string Runtime::bundle_name(BundleId bundle) const {
  std::lock_guard lock(mutex_);
  return scheduler_.model().bundle(bundle).name;
}

AddedIds Runtime::add(const ModelAddition& addition, std::map<std::string, AppletRunner> runners) {
  for (const auto& [name, runner] : runners) {
    const bool added = std::any_of(addition.applets.begin(), addition.applets.end(),
                                   [&](const NewApplet& a) { return a.name == name; });
    if (!added) {
      throw std::invalid_argument("a runner for applet '" + name + "', which is not added");
    }
    if (runner.code.has_value() == static_cast<bool>(runner.forward)) {
      throw std::invalid_argument("applet '" + name +
                                  "': a runner has either code or a forward, not both or none");
    }
    if (runner.code && !runner.code->step) {
      throw std::invalid_argument("applet '" + name + "': code needs a step");
    }
  }
  std::unique_lock lock(mutex_);
  AddedIds ids;
  locked_call([&](Scheduler& s) { ids = s.add(addition); });
  while (slots_.size() < scheduler_.model().applets().size()) {
    slots_.push_back(std::make_unique<Slot>());
  }
  waiting_since_.resize(scheduler_.model().bundles().size());
  granted_at_.resize(scheduler_.model().bundles().size());
  for (const AppletId id : ids.applets) {
    const auto it = runners.find(scheduler_.model().applet(id).name);
    if (it == runners.end()) continue;
    Slot* slot = slots_[id].get();
    if (it->second.forward) {
      slot->forward = std::move(it->second.forward);
      continue;
    }
    slot->code = std::move(*it->second.code);
    slot->has_code = true;
    if (running_ && !stopping_) {
      slot->thread = std::thread([this, id, slot] { applet_main(id, *slot); });
    }
  }
  wake(lock);
  return ids;
}

void Runtime::remove_applet(const std::string& applet) {
  std::thread ending;
  {
    std::unique_lock lock(mutex_);
    const AppletId id = scheduler_.model().applet_id(applet);
    Slot& slot = *slots_[id];
    if (slot.thread.joinable() && slot.thread.get_id() == std::this_thread::get_id()) {
      throw std::invalid_argument("applet '" + applet +
                                  "' cannot remove itself (its thread would wait for itself)");
    }
    locked_call([&](Scheduler& s) { s.remove_applet(id); });
    slot.removed = true;
    slot.forward = nullptr;
    slot.interrupts.clear();
    slot.cv.notify_all();  // a step waiting in use() or between steps ends
    ending = std::move(slot.thread);
    wake(lock);
  }
  if (ending.joinable()) ending.join();
}

void Runtime::remove_service(const std::string& service) {
  with_scheduler([&](Scheduler& s) { s.remove_service(s.model().service_id(service)); });
}

RuntimeStats Runtime::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

// The applet wrapper (seed §4.6.2 "Fail-Stop"): whatever the code throws — a std::exception or
// anything else (`throw 42`) — ends this applet only; its bundles are released and everything
// else goes on.
void Runtime::applet_main(AppletId id, Slot& slot) {
  RuntimeContext ctx(*this, id);
  try {
    if (slot.code.init) slot.code.init(ctx);  // Abb. 4.12 lines 1–3
    auto next = Clock::now();
    for (;;) {
      std::deque<Notification> queue;
      {
        std::unique_lock lock(mutex_);
        if (stopping_ || slot.removed) return;
        queue.swap(slot.interrupts);
      }
      for (const Notification& n : queue) {  // Abb. 4.12 line 4: interrupt handlers first
        if (is_revocation(n.kind)) slot.reacting_to_revocation = n.bundle;
        if (slot.code.on_interrupt) {
          slot.code.on_interrupt(ctx, n);
        } else if (n.kind == Notification::Kind::kRevokeRequested) {
          ctx.yield(bundle_name(n.bundle));
        }
        slot.reacting_to_revocation.reset();
      }
      run_negotiations(ctx);  // follow-up rounds run like interrupt handlers (§4.5.3)
      if (Clock::now() >= next) {
        bool paused;
        {
          std::lock_guard lock(mutex_);
          paused = slot.paused;
        }
        if (!paused) slot.code.step(ctx);  // line 5
        ++slot.steps;
        next += slot.code.period;  // lines 6–7
      }
      // An interrupt wakes the applet at once: its handler runs now, between two steps, and the
      // steps keep their period (a holder asked to give a service back need not wait a period).
      std::unique_lock lock(mutex_);
      slot.cv.wait_until(lock, next,
                         [&] { return stopping_ || slot.removed || !slot.interrupts.empty(); });
      if (stopping_ || slot.removed) return;
    }
  } catch (...) {  // the boundary of the applet: nothing may escape into the process
    std::unique_lock lock(mutex_);
    if (slot.removed) return;  // its calls were refused because it was removed: not a crash
    slot.crashed = true;
    stats_.crashed.push_back(scheduler_.model().applet(id).name);
    locked_call([id](Scheduler& s) { s.crash(id); });
    wake(lock);
  }
}

std::optional<Notification> Runtime::run_round(AppletContext& ctx, BundleId bundle,
                                               const NegotiationRound& round) {
  Slot& slot = slot_of(ctx.id());
  const std::string name = bundle_name(bundle);
  const SchedulerOptions& options = scheduler_.options();
  const auto started = Clock::now();
  if (round.first) round.first();
  std::optional<Notification> reply;
  // A round whose code overran the round limit is not answered: the chain ends (seed §4.5.3).
  if (Clock::now() - started <= options.negotiation_round_max) {
    // Checked and answered under one lock: a forced revocation cannot slip in between.
    with_scheduler([&](Scheduler& s) {
      if (s.revoke_deadline(bundle)) reply = s.negotiate(bundle, round.answer);
    });
  }
  Slot::Chain& chain = slot.negotiations[bundle];
  ++chain.rounds;
  chain.step = slot.steps;
  chain.round_started = started;
  chain.next.reset();
  if (reply) {
    chain.next =
        reply->kind == Notification::Kind::kNegotiationAccepted ? round.on_accept : round.on_reject;
  }
  if (!chain.next || chain.rounds >= options.negotiation_rounds_max) {
    slot.negotiations.erase(bundle);
    ctx.yield(name);  // the defined behaviour has run (or may not go on): hand the bundle over
  }
  return reply;
}

void Runtime::run_negotiations(AppletContext& ctx) {
  Slot& slot = slot_of(ctx.id());
  const auto round_max = scheduler_.options().negotiation_round_max;
  for (auto it = slot.negotiations.begin(); it != slot.negotiations.end();) {
    const auto current = it++;  // run_round may erase `current`, never another entry
    const BundleId bundle = current->first;
    Slot::Chain& chain = current->second;
    if (chain.step >= slot.steps) continue;  // one round per main-loop step
    const std::string name = bundle_name(bundle);
    if (!ctx.being_revoked(name)) {  // forced meanwhile, or the plan gave the bundle back
      slot.negotiations.erase(current);
      continue;
    }
    if (Clock::now() - chain.round_started > round_max) {  // the round took too long
      slot.negotiations.erase(current);
      ctx.yield(name);
      continue;
    }
    const auto next = chain.next;  // keeps the round alive while it runs
    slot.reacting_to_revocation = bundle;
    run_round(ctx, bundle, *next);
    slot.reacting_to_revocation.reset();
  }
}

// Follows the clock: the reassigners revoke by force when a wait limit passes (seed §4.6.1),
// requests expire at t_finish and are planned at t_early (§4.5.1).
void Runtime::reassigner_main() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    forcing_at_ = scheduler_.next_event().value_or(milliseconds::max());
    if (forcing_at_ == milliseconds::max()) {
      changed_.wait(lock);
    } else {
      changed_.wait_until(lock, start_ + forcing_at_);
    }
    if (stopping_) break;
    scheduler_.advance_to(std::max(scheduler_.now(), clock()));
    deliver();
    wake(lock);
    lock.lock();
  }
}

}  // namespace oscar::applets
