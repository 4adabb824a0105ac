#include "applet_host_impl.hpp"

namespace oscar::coordinator {
namespace {

ConfigReply refused(const std::string& module, const std::string& why) {
  ConfigReply r;
  r.module_name(module);
  r.ok(false);
  r.error(why);
  return r;
}

}  // namespace

// The applet's calls, over DDS to the coordinator.
class AppletHost::Impl::Context final : public applets::AppletContext {
 public:
  Context(Impl& host, Hosted& h) : host_(host), h_(h) {}

  void request(const std::string& bundle) override {
    bundle_id(bundle);
    bool was;
    {
      std::lock_guard lock(host_.mutex_);
      was = h_.requested[bundle];
      h_.requested[bundle] = true;
    }
    const auto reply = host_.call(h_, make("request", bundle));
    if (reply && !reply->ok()) {
      std::lock_guard lock(host_.mutex_);
      h_.requested[bundle] = was;
      throw std::invalid_argument(reply->error());
    }
  }
  void release(const std::string& bundle) override {
    bundle_id(bundle);
    {
      std::lock_guard lock(host_.mutex_);
      h_.requested[bundle] = false;
      auto it = h_.bundles.find(bundle);
      if (it != h_.bundles.end()) it->second.active(false);  // not to be used from now on
    }
    host_.call(h_, make("release", bundle));
  }
  void yield(const std::string& bundle) override {
    bundle_id(bundle);
    {
      std::lock_guard lock(host_.mutex_);
      auto it = h_.bundles.find(bundle);
      if (it != h_.bundles.end()) it->second.active(false);
    }
    host_.call(h_, make("yield", bundle));
  }
  void trigger(const std::string& bundle) override {
    bundle_id(bundle);
    refuse_reprioritising(bundle, "triggers");
    checked(host_.call(h_, make("trigger", bundle)));
  }
  void set_priority(const std::string& bundle, int priority) override {
    bundle_id(bundle);
    refuse_reprioritising(bundle, "changes the priority of");
    auto c = make("set_priority", bundle);
    c.priority(priority);
    checked(host_.call(h_, c));
    std::lock_guard lock(host_.mutex_);
    h_.settings[bundle].priority = priority;
  }
  void set_deadline(const std::string& bundle, std::optional<applets::Deadline> d) override {
    bundle_id(bundle);
    auto c = make("set_deadline", bundle);
    c.has_deadline(d.has_value());
    if (d) {
      c.t_early_ms(d->t_early.count());
      c.t_duration_ms(d->t_duration.count());
      c.t_finish_ms(d->t_finish.count());
    }
    checked(host_.call(h_, c));
    std::lock_guard lock(host_.mutex_);
    h_.settings[bundle].deadline = d;
  }
  Notification negotiate(const std::string& bundle, const applets::Negotiation& answer) override {
    const BundleId b = bundle_id(bundle);
    auto c = make("negotiate", bundle);
    c.min_needed_ms(answer.min_needed.count());
    c.max_needed_ms(answer.max_needed.count());
    c.accept(answer.accept);
    const auto reply = host_.call(h_, c);
    if (!reply) throw std::invalid_argument("no reply from the coordinator to a negotiation");
    checked(reply);
    Notification n;
    n.kind =
        internal::notice_kind(reply->kind()).value_or(Notification::Kind::kNegotiationRejected);
    n.applet = h_.id;
    n.bundle = b;
    n.until = milliseconds(reply->until_ms());
    return n;
  }
  std::optional<Notification> negotiate(const std::string& bundle,
                                        const applets::NegotiationRound& round) override {
    const BundleId b = bundle_id(bundle);
    if (h_.negotiations.count(b) != 0) return std::nullopt;
    return host_.run_round(*this, h_, b, round);
  }
  bool negotiating(const std::string& bundle) const override {
    return h_.negotiations.count(bundle_id(bundle)) != 0;
  }
  bool being_revoked(const std::string& bundle) const override {
    bundle_id(bundle);
    std::lock_guard lock(host_.mutex_);
    const auto it = h_.bundles.find(bundle);
    return it != h_.bundles.end() && it->second.revoking();
  }
  bool use(const std::string& bundle, const std::function<void()>& body) override {
    bundle_id(bundle);
    {
      std::unique_lock lock(host_.mutex_);
      auto active = [&] {
        const auto it = h_.bundles.find(bundle);
        return it != h_.bundles.end() && it->second.active();
      };
      if (!active()) {
        if (h_.fail_stop) {
          throw applets::ResourceRevoked("applet '" + h_.name + "' used bundle '" + bundle +
                                         "' which is not granted (fail-stop)");
        }
        while (!active()) {
          if (host_.stopping_) return false;
          host_.wait(h_, lock, kSlice, active);
        }
      }
    }
    body();
    return true;
  }
  bool granted(const std::string& bundle) const override {
    bundle_id(bundle);
    std::lock_guard lock(host_.mutex_);
    const auto it = h_.bundles.find(bundle);
    return it != h_.bundles.end() && it->second.active();
  }
  AppletId id() const override { return h_.id; }

  // Between steps: the interrupt being handled (seed footnote 11).
  void reacting(std::optional<BundleId> b) { h_.reacting_to_revocation = b; }

 private:
  BundleId bundle_id(const std::string& bundle) const {
    return host_.config_.model.bundle_id(h_.id, bundle);
  }
  SchedCall make(const char* what, const std::string& bundle) const {
    SchedCall c;
    c.call(what);
    c.bundle(bundle);
    return c;
  }
  static void checked(const std::optional<SchedReply>& reply) {
    if (reply && !reply->ok()) throw std::invalid_argument(reply->error());
  }
  void refuse_reprioritising(const std::string& bundle, const char* what) const {
    const auto& revoked = h_.reacting_to_revocation;
    if (!revoked) return;
    throw std::invalid_argument(
        "applet '" + h_.name + "' " + what + " bundle '" + bundle +
        "' while it reacts to the revocation of its bundle '" +
        host_.config_.model.bundle(*revoked).name +
        "'; an applet never re-prioritises in reaction to a revocation (seed 000 §4.5.2, "
        "footnote 11: it would make the plan oscillate) — yield or negotiate instead");
  }

  Impl& host_;
  Hosted& h_;
};

void AppletHost::Impl::pump(Hosted& h) {
  std::optional<SchedHello> hello;
  std::optional<SchedBeat> beat;
  {
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();
    if (h.crashed) return;
    if (!h.welcomed && now - h.last_hello >= kHelloAgain) {
      h.last_hello = now;
      hello.emplace();
      hello->applet(h.name);
      hello->process(process_);
      hello->session(h.session);
      hello->spec(h.spec);
      for (const auto& [bundle, asked] : h.requested) {
        if (!asked) continue;
        SchedWish w;
        w.bundle(bundle);
        const auto& s = h.settings[bundle];
        w.has_priority(s.priority.has_value());
        w.priority(s.priority.value_or(0));
        w.has_deadline(s.deadline.has_value());
        if (s.deadline) {
          w.t_early_ms(s.deadline->t_early.count());
          w.t_duration_ms(s.deadline->t_duration.count());
          w.t_finish_ms(s.deadline->t_finish.count());
        }
        hello->wishes().push_back(std::move(w));
      }
    } else if (h.welcomed && now - h.last_beat >= beat_every_) {
      h.last_beat = now;
      beat.emplace();
      beat->applet(h.name);
      beat->session(h.session);
    }
  }
  if (hello) hello_writer_.write(*hello);
  if (beat) beat_writer_.write(*beat);
}

bool AppletHost::Impl::wait(Hosted& h, std::unique_lock<std::mutex>& lock, Clock::duration timeout,
                            const std::function<bool()>& ready) {
  const auto until = Clock::now() + timeout;
  while (!ready()) {
    if (stopping_ || Clock::now() >= until) return false;
    lock.unlock();
    pump(h);
    lock.lock();
    h.cv.wait_for(lock, std::min<Clock::duration>(kSlice, until - Clock::now()),
                  [&] { return stopping_ || ready(); });
  }
  return true;
}

void AppletHost::Impl::apply_state(Hosted& h, std::uint64_t coordinator, std::uint64_t seq,
                                   const std::vector<SchedBundleState>& bundles) {
  if (coordinator == h.coordinator && seq <= h.state_seq) return;  // older than what it knows
  h.coordinator = coordinator;
  h.state_seq = seq;
  for (const auto& b : bundles) h.bundles[b.bundle()] = b;
  h.cv.notify_all();
}

std::optional<SchedReply> AppletHost::Impl::call(Hosted& h, SchedCall c) {
  std::unique_lock lock(mutex_);
  if (!h.welcomed) return std::nullopt;  // announced with the next hello
  const auto seq = h.next_seq++;
  c.applet(h.name);
  c.session(h.session);
  c.seq(seq);
  lock.unlock();
  call_writer_.write(c);
  lock.lock();
  if (!wait(h, lock, kCallTimeout, [&] { return h.replies.contains(seq); })) {
    if (!stopping_) {
      spdlog::warn(
          "applet {}: no reply from the coordinator to '{}' of bundle '{}'; announcing "
          "it again",
          h.name, c.call(), c.bundle());
      h.welcomed = false;
    }
    return std::nullopt;
  }
  auto reply = std::move(h.replies.at(seq));
  h.replies.erase(seq);
  if (!reply.ok() && reply.kind() == "announce") {  // the coordinator does not know it (now)
    h.welcomed = false;
    return std::nullopt;
  }
  return reply;
}

void AppletHost::Impl::on_reply(const SchedReply& r) {
  const auto it = hosted_.find(r.applet());
  if (it == hosted_.end()) return;
  auto& h = *it->second;
  std::lock_guard lock(mutex_);
  if (r.session() != h.session) return;
  apply_state(h, r.coordinator(), r.state_seq(), r.bundles());
  h.replies[r.seq()] = r;
  h.cv.notify_all();
}

void AppletHost::Impl::on_command_reply(const SchedCommandReply& r) {
  const auto it = hosted_.find(r.applet());
  if (it == hosted_.end()) return;
  auto& h = *it->second;
  std::lock_guard lock(mutex_);
  if (r.session() != h.session) return;
  h.command_replies[r.seq()] = r;
  h.cv.notify_all();
}

void AppletHost::Impl::on_notice(const SchedNotice& n) {
  const auto it = hosted_.find(n.applet());
  if (it == hosted_.end()) return;
  auto& h = *it->second;
  std::lock_guard lock(mutex_);
  if (n.session() != h.session) return;  // meant for another start of this applet
  if (n.kind() == "announce") {
    h.welcomed = false;
    h.last_hello = {};
    return;
  }
  apply_state(h, n.coordinator(), n.state_seq(), n.bundles());
  if (n.kind() == "welcome") {
    if (!h.welcomed) spdlog::info("applet {}: announced to the coordinator", h.name);
    h.welcomed = true;
    return;
  }
  h.notices.push_back(n);
  h.cv.notify_all();
}

Notification AppletHost::Impl::notification_of(const Hosted& h, const SchedNotice& n) const {
  const auto& m = config_.model;
  Notification out;
  out.kind = *internal::notice_kind(n.kind());
  out.applet = h.id;
  out.bundle = m.bundle_id(h.id, n.bundle());
  for (const auto& a : n.new_holders()) out.new_holders.push_back(m.applet_id(a));
  if (!n.other().empty()) {
    const auto slash = n.other().find('/');
    out.other = m.bundle_id(m.applet_id(n.other().substr(0, slash)), n.other().substr(slash + 1));
  }
  out.until = milliseconds(n.until_ms());
  if (!n.service().empty()) out.service = m.service_id(n.service());
  return out;
}

std::optional<Notification> AppletHost::Impl::run_round(Context& ctx, Hosted& h, BundleId bundle,
                                                        const applets::NegotiationRound& round) {
  const auto& name = config_.model.bundle(bundle).name;
  const auto& options = config_.options;
  const auto started = Clock::now();
  if (round.first) round.first();
  std::optional<Notification> reply;
  // A round whose code overran the round limit is not answered: the chain ends (seed §4.5.3).
  if (Clock::now() - started <= options.negotiation_round_max) {
    try {
      reply = ctx.negotiate(name, round.answer);
    } catch (const std::invalid_argument&) {
      // No longer being revoked (forced or given back meanwhile), or no coordinator: no answer.
    }
  }
  Chain& chain = h.negotiations[bundle];
  ++chain.rounds;
  chain.step = h.steps;
  chain.round_started = started;
  chain.next.reset();
  if (reply) {
    chain.next =
        reply->kind == Notification::Kind::kNegotiationAccepted ? round.on_accept : round.on_reject;
  }
  if (!chain.next || chain.rounds >= options.negotiation_rounds_max) {
    h.negotiations.erase(bundle);
    ctx.yield(name);  // the defined behaviour has run (or may not go on): hand the bundle over
  }
  return reply;
}

void AppletHost::Impl::run_negotiations(Context& ctx, Hosted& h) {
  const auto round_max = config_.options.negotiation_round_max;
  for (auto it = h.negotiations.begin(); it != h.negotiations.end();) {
    const auto current = it++;  // run_round may erase `current`, never another entry
    const BundleId bundle = current->first;
    Chain& chain = current->second;
    if (chain.step >= h.steps) continue;  // one round per main-loop step
    const auto& name = config_.model.bundle(bundle).name;
    if (!ctx.being_revoked(name)) {
      h.negotiations.erase(current);
      continue;
    }
    if (Clock::now() - chain.round_started > round_max) {
      h.negotiations.erase(current);
      ctx.yield(name);
      continue;
    }
    const auto next = chain.next;
    ctx.reacting(bundle);
    run_round(ctx, h, bundle, *next);
    ctx.reacting(std::nullopt);
  }
}

bool AppletHost::Impl::apply_event(Context& ctx, Hosted& h, const SchedNotice& n) {
  const AppletEvent& e = n.args();
  const auto& what = e.event();
  if (what == "crash") return false;
  std::string error;
  try {
    if (what == "request") ctx.request(e.bundle());
    if (what == "release") ctx.release(e.bundle());
    if (what == "trigger") ctx.trigger(e.bundle());
    if (what == "yield") ctx.yield(e.bundle());
    if (what == "set_priority") ctx.set_priority(e.bundle(), e.priority());
    if (what == "set_deadline") {
      std::optional<applets::Deadline> d;
      if (e.has_deadline()) {
        d = applets::Deadline{milliseconds(e.t_early_ms()), milliseconds(e.t_duration_ms()),
                              milliseconds(e.t_finish_ms())};
      }
      ctx.set_deadline(e.bundle(), d);
    }
    if (what == "negotiate") {
      applets::Negotiation answer;
      answer.min_needed = milliseconds(e.min_ms());
      answer.max_needed = milliseconds(e.max_ms());
      answer.accept = e.accept();
      const auto reply = ctx.negotiate(e.bundle(), answer);
      spdlog::info("applet {}: {} {}", h.name, e.bundle(), internal::notice_kind(reply.kind));
    }
  } catch (const std::invalid_argument& x) {
    error = x.what();
    spdlog::warn("applet {}: {} {}: {}", h.name, what, e.bundle(), error);
  }
  SchedCall done;
  done.call("event_done");
  done.event_id(n.event_id());
  done.error(error);
  call(h, done);
  return true;
}

// The applet's loop, as in the coordinator's Runtime (seed Abb. 4.12): interrupts as they come,
// a step every period; whatever the code throws ends this applet only (it loses its bundles).
void AppletHost::Impl::applet_main(Hosted& h) {
  Context ctx(*this, h);
  Applet& applet = *h.applet;
  std::uint64_t crash_event = 0;  // the operator's event "crash" that ended the applet, if any
  try {
    {
      // Announced first, so that init()'s calls reach a coordinator that knows the applet.
      std::unique_lock lock(mutex_);
      lock.unlock();
      pump(h);
      lock.lock();
      wait(h, lock, kCallTimeout, [&] { return h.welcomed; });
      if (stopping_) return;
    }
    applet.init(ctx);
    auto next = Clock::now();
    for (;;) {
      pump(h);
      std::deque<SchedNotice> queue;
      {
        std::lock_guard lock(mutex_);
        if (stopping_) return;
        queue.swap(h.notices);
      }
      for (const auto& n : queue) {
        if (n.kind() == "event") {  // an operator's event: the applet's own call
          if (apply_event(ctx, h, n)) continue;
          crash_event = n.event_id();
          throw std::runtime_error("an operator's event 'crash' made its code throw");
        }
        if (!internal::notice_kind(n.kind())) continue;  // a kind this build does not know
        const auto notification = notification_of(h, n);
        if (internal::is_revocation(notification.kind)) ctx.reacting(notification.bundle);
        if (!applet.on_interrupt(ctx, notification) &&
            notification.kind == Notification::Kind::kRevokeRequested) {
          ctx.yield(n.bundle());
        }
        ctx.reacting(std::nullopt);
      }
      run_negotiations(ctx, h);
      if (Clock::now() >= next) {
        applet.step(ctx);
        ++h.steps;
        next += applet.period();
      }
      std::unique_lock lock(mutex_);
      while (!stopping_ && Clock::now() < next) {
        lock.unlock();
        pump(h);
        lock.lock();
        h.cv.wait_until(lock, std::min(next, Clock::now() + kSlice),
                        [&] { return stopping_ || !h.notices.empty(); });
        // Interrupts run at once, between two steps; the steps keep their period.
        if (!h.notices.empty()) break;
      }
      if (stopping_) return;
    }
  } catch (const std::exception& e) {
    spdlog::error("applet {}: crashed: {}; its bundles are released", h.name, e.what());
  } catch (...) {
    spdlog::error("applet {}: crashed (not a std::exception); its bundles are released", h.name);
  }
  SchedCall c;
  c.call("crash");
  call(h, c);
  if (crash_event != 0) {
    SchedCall done;
    done.call("event_done");
    done.event_id(crash_event);
    call(h, done);
  }
  std::lock_guard lock(mutex_);
  h.requested.clear();
  h.crashed = true;  // no hello again: a crashed applet stays out until its process restarts
}

ConfigReply AppletHost::Impl::command(const std::string& applet, const std::string& service,
                                      const std::string& module, const std::string& kernel,
                                      const std::string& command, const std::string& type,
                                      std::vector<std::uint8_t> cdr) {
  SchedCommand c;
  c.applet(applet);
  c.service(service);
  c.module_name(module);
  c.kernel(kernel);
  c.command(command);
  c.payload_type(type);
  c.payload(std::move(cdr));
  return send(std::move(c));
}

ConfigReply AppletHost::Impl::trigger(const std::string& applet, const std::string& service,
                                      const std::string& module, const std::string& kernel) {
  SchedCommand c;
  c.applet(applet);
  c.service(service);
  c.module_name(module);
  c.kernel(kernel);
  c.trigger(true);
  return send(std::move(c));
}

ConfigReply AppletHost::Impl::send(SchedCommand c) {
  const auto applet = c.applet();
  const auto module = c.module_name();
  auto& h = hosted(applet);
  std::unique_lock lock(mutex_);
  if (!h.welcomed) {
    return refused(module,
                   fmt::format("applet '{}' is not announced to the coordinator (yet)", applet));
  }
  const auto seq = h.next_seq++;
  c.session(h.session);
  c.seq(seq);
  lock.unlock();
  command_writer_.write(c);
  lock.lock();
  if (!wait(h, lock, kCommandTimeout, [&] { return h.command_replies.contains(seq); })) {
    return refused(
        module, fmt::format("no reply from the coordinator within {} ms", kCommandTimeout.count()));
  }
  auto reply = h.command_replies.at(seq).reply();
  h.command_replies.erase(seq);
  return reply;
}

}  // namespace oscar::coordinator
