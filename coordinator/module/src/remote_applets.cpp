#include "remote_applets.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "sched_wire.hpp"

namespace oscar::coordinator {
namespace {

using applets::AppletId;
using applets::BundleId;
using applets::Notification;
using Clock = std::chrono::steady_clock;

constexpr std::chrono::milliseconds kWorkerTick{20};
// How often an applet the coordinator does not know is asked to announce itself.
constexpr std::chrono::milliseconds kAskAgain{300};
// How long the command port `applet` waits for a remote applet to apply an operator's event.
constexpr std::chrono::milliseconds kEventTimeout{3000};

SchedNotice notice_of(const applets::Model& m, const Notification& n) {
  SchedNotice out;
  out.kind(internal::notice_kind(n.kind));
  out.bundle(m.bundle(n.bundle).name);
  if (n.service) out.service(m.service(*n.service).name);
  for (const AppletId a : n.new_holders) out.new_holders().push_back(m.applet(a).name);
  if (n.other) {
    const auto& other = m.bundle(*n.other);
    out.other(m.applet(other.applet).name + "/" + other.name);
  }
  out.until_ms(n.until.count());
  return out;
}

}  // namespace

RemoteApplets::RemoteApplets(const SystemSpec& system, applets::Runtime& runtime,
                             AppletGateway& gateway, DdsParticipant& participant,
                             std::function<void()> changed, Membership membership)
    : system_(system),
      runtime_(runtime),
      gateway_(gateway),
      changed_(std::move(changed)),
      membership_(std::move(membership)),
      lease_(system.coordinator ? system.coordinator->applet_lease
                                : std::chrono::milliseconds(1500)),
      coordinator_id_(internal::fresh_id()),
      reply_writer_(participant, topics::sched_reply()),
      notice_writer_(participant, topics::sched_notice()),
      command_reply_writer_(participant, topics::sched_command_reply()) {
  if (system.coordinator) {
    for (const auto& a : system.coordinator->applets) {
      if (!a.remote()) continue;
      Applet entry;
      runtime_.with_scheduler(
          [&](applets::Scheduler& s) { entry.id = s.model().applet_id(a.name); });
      entry.process = a.process;
      applets_.emplace(a.name, entry);
      runtime_.set_remote(a.name, forwarder(a.name));
    }
  }
  // Listening also without applets of the file's: applets may join from other processes.
  hello_reader_ = std::make_unique<TopicReader<SchedHello, SchedHelloPubSubType>>(
      participant, topics::sched_hello(), [this](const SchedHello& h, const auto&) {
        std::lock_guard lock(mutex_);
        inbound_.push_back([this, h] { on_hello(h); });
        wake_.notify_all();
      });
  call_reader_ = std::make_unique<TopicReader<SchedCall, SchedCallPubSubType>>(
      participant, topics::sched_call(), [this](const SchedCall& c, const auto&) {
        std::lock_guard lock(mutex_);
        inbound_.push_back([this, c] { on_call(c); });
        wake_.notify_all();
      });
  command_reader_ = std::make_unique<TopicReader<SchedCommand, SchedCommandPubSubType>>(
      participant, topics::sched_command(), [this](const SchedCommand& c, const auto&) {
        std::lock_guard lock(mutex_);
        commands_.push_back(c);
        wake_.notify_all();
      });
  beat_reader_ = std::make_unique<TopicReader<SchedBeat, SchedBeatPubSubType>>(
      participant, topics::sched_beat(), [this](const SchedBeat& b, const auto&) { on_beat(b); });
}

RemoteApplets::~RemoteApplets() {
  stop();
  // No callback into a half-destroyed object.
  hello_reader_.reset();
  call_reader_.reset();
  command_reader_.reset();
  beat_reader_.reset();
}

std::function<void(const Notification&)> RemoteApplets::forwarder(const std::string& applet) {
  return [this, applet](const Notification& n) {
    // Under the runtime's lock: only queue.
    std::lock_guard lock(mutex_);
    outgoing_.push_back({applet, n, {}});
    wake_.notify_all();
  };
}

void RemoteApplets::adopt(const std::string& applet, AppletId id, const std::string& process) {
  std::lock_guard lock(mutex_);
  Applet entry;
  entry.id = id;
  entry.process = process;
  entry.joined = true;
  applets_[applet] = entry;
}

void RemoteApplets::forget(const std::string& applet, bool refuse_session) {
  std::lock_guard lock(mutex_);
  const auto it = applets_.find(applet);
  if (it == applets_.end()) return;
  if (refuse_session && it->second.joined) refused_[applet] = it->second.session;
  applets_.erase(it);
}

bool RemoteApplets::joined(const std::string& applet) const {
  std::lock_guard lock(mutex_);
  const auto it = applets_.find(applet);
  return it != applets_.end() && it->second.joined;
}

void RemoteApplets::start() {
  std::lock_guard lock(mutex_);
  if (started_) return;
  started_ = true;
  worker_ = std::thread([this] { worker(); });
  commands_thread_ = std::thread([this] { commands(); });
}

void RemoteApplets::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  events_done_.notify_all();
  if (worker_.joinable()) worker_.join();
  if (commands_thread_.joinable()) commands_thread_.join();
}

bool RemoteApplets::remote(const std::string& applet) const {
  std::lock_guard lock(mutex_);
  return applets_.contains(applet);
}

RemoteApplets::Seen RemoteApplets::seen(const std::string& applet) const {
  std::lock_guard lock(mutex_);
  const auto& a = applets_.at(applet);
  if (a.crashed) return {a.process, "crashed"};
  if (!a.present) return {a.process, "absent"};
  return {a.process, std::nullopt};
}

std::optional<std::string> RemoteApplets::event(const AppletEvent& e) {
  const auto& applet = e.applet();
  std::uint64_t session = 0;
  {
    std::lock_guard lock(mutex_);
    const auto it = applets_.find(applet);
    if (it == applets_.end()) return fmt::format("unknown applet '{}'", applet);
    const auto& a = it->second;
    if (!a.present) {
      return fmt::format(
          "applet '{}' runs in process '{}', which the coordinator does not hear "
          "from now",
          applet, a.process);
    }
    session = a.session;
  }
  if (e.event() != "crash") {
    try {
      runtime_.with_scheduler([&](applets::Scheduler& s) {
        s.model().bundle_id(s.model().applet_id(applet), e.bundle());  // throws if unknown
      });
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
  }
  if (!internal::known_applet_event(e.event())) {
    return fmt::format("unknown event '{}' (events: {})", e.event(), internal::kAppletEvents);
  }
  std::uint64_t id = 0;
  {
    std::lock_guard lock(mutex_);
    id = next_event_id_++;
    events_[id] = std::nullopt;
  }
  SchedNotice n;
  n.applet(applet);
  n.session(session);
  n.kind("event");
  n.bundle(e.bundle());
  n.event(e.event());
  n.args(e);
  n.event_id(id);
  send({applet, std::nullopt, std::move(n)});
  // The reply waits for the applet's word, so that events sent one after the other are applied
  // in that order (a scenario's timeline), and a refused call is the event's refusal.
  std::unique_lock lock(mutex_);
  const bool done = events_done_.wait_for(lock, kEventTimeout,
                                          [&] { return stopping_ || events_.at(id).has_value(); });
  const auto result = events_.at(id);
  events_.erase(id);
  if (!done || !result) {
    return fmt::format("applet '{}' did not confirm the event '{}' within {} ms", applet, e.event(),
                       kEventTimeout.count());
  }
  if (!result->empty()) return *result;
  return std::nullopt;
}

bool RemoteApplets::current(const std::string& applet, std::uint64_t session) {
  std::lock_guard lock(mutex_);
  const auto it = applets_.find(applet);
  return it != applets_.end() && it->second.present && it->second.session == session;
}

void RemoteApplets::on_beat(const SchedBeat& beat) {
  std::lock_guard lock(mutex_);
  const auto now = Clock::now();
  const auto it = applets_.find(beat.applet());
  if (it == applets_.end()) {
    // An applet that joined by its hello before this coordinator started (or before its lease
    // ran out), or one of the file's that runs here: its hello says which.
    auto& asked = unknown_asked_[beat.applet()];
    if (now - asked < kAskAgain) return;
    asked = now;
    SchedNotice n;
    n.applet(beat.applet());
    n.session(beat.session());
    n.kind("announce");
    outgoing_.push_back({beat.applet(), std::nullopt, std::move(n)});
    wake_.notify_all();
    return;
  }
  auto& a = it->second;
  if (a.present && a.session == beat.session()) {
    a.last_beat = now;
    return;
  }
  // A process the coordinator does not know (it restarted, or the lease ran out): ask it to
  // announce itself again, with what it asks for.
  if (now - a.last_announce_asked < kAskAgain) return;
  a.last_announce_asked = now;
  SchedNotice n;
  n.applet(beat.applet());
  n.session(beat.session());
  n.kind("announce");
  outgoing_.push_back({beat.applet(), std::nullopt, std::move(n)});
  wake_.notify_all();
}

void RemoteApplets::take_bundles(AppletId id) {
  runtime_.with_scheduler([&](applets::Scheduler& s) {
    for (const BundleId b : s.model().applet(id).bundles) {
      if (s.requested(b) || s.active(b) || s.revoke_deadline(b)) s.release(b);
    }
  });
}

void RemoteApplets::on_hello(const SchedHello& hello) {
  AppletId id = 0;
  bool replaced = false;
  bool is_known = false;
  {
    std::lock_guard lock(mutex_);
    is_known = applets_.contains(hello.applet());
    const auto refused = refused_.find(hello.applet());
    if (!is_known && refused != refused_.end() && refused->second == hello.session()) return;
  }
  if (!is_known && !hello.spec().empty() && membership_.join) {
    // An applet the file does not configure joins: the coordinator adds it (seed 000 §4.1.1).
    if (const auto error = membership_.join(hello.applet(), hello.process(), hello.spec())) {
      spdlog::warn("coordinator: applet '{}' in process '{}' cannot join: {}", hello.applet(),
                   hello.process(), *error);
      std::lock_guard lock(mutex_);
      refused_[hello.applet()] = hello.session();  // told once; a new start may try again
      return;
    }
    spdlog::info("coordinator: applet '{}' in process '{}' joined", hello.applet(),
                 hello.process());
  }
  {
    std::lock_guard lock(mutex_);
    const auto it = applets_.find(hello.applet());
    if (it == applets_.end()) {
      spdlog::warn(
          "coordinator: a hello from applet '{}' in process '{}': the system file runs "
          "no such applet in another process",
          hello.applet(), hello.process());
      return;
    }
    auto& a = it->second;
    id = a.id;
    replaced = a.present && a.session != hello.session();
    a.session = hello.session();
    a.process = hello.process();
    a.present = true;
    a.crashed = false;
    a.last_beat = Clock::now();
  }
  // A new start of the applet's process: what the old one held is gone with it.
  if (replaced) {
    spdlog::warn(
        "coordinator: applet '{}' announced itself from a new start of process '{}': "
        "what the old one held is taken",
        hello.applet(), hello.process());
    take_bundles(id);
  }
  SchedNotice welcome;
  welcome.applet(hello.applet());
  welcome.session(hello.session());
  welcome.kind("welcome");
  runtime_.with_scheduler([&](applets::Scheduler& s) {
    const auto& m = s.model();
    const auto& bundles = m.applet(id).bundles;
    for (const BundleId b : bundles) {
      const auto& name = m.bundle(b).name;
      const SchedWish* wish = nullptr;
      for (const auto& w : hello.wishes()) {
        if (w.bundle() == name) wish = &w;
      }
      try {
        if (!wish) {
          if (s.requested(b)) s.release(b);
          continue;
        }
        if (wish->has_priority()) s.set_priority(b, wish->priority());
        if (wish->has_deadline()) {
          s.set_deadline(b, applets::Deadline{std::chrono::milliseconds(wish->t_early_ms()),
                                              std::chrono::milliseconds(wish->t_duration_ms()),
                                              std::chrono::milliseconds(wish->t_finish_ms())});
        }
        if (!s.requested(b)) s.request(b);
      } catch (const std::invalid_argument& e) {
        spdlog::warn("coordinator: applet '{}' asks for bundle '{}': {}", hello.applet(), name,
                     e.what());
      }
    }
    for (const auto& w : hello.wishes()) {
      const bool known = std::any_of(bundles.begin(), bundles.end(),
                                     [&](BundleId b) { return m.bundle(b).name == w.bundle(); });
      if (!known) {
        spdlog::warn("coordinator: applet '{}' asks for bundle '{}', which it does not have",
                     hello.applet(), w.bundle());
      }
    }
    std::uint64_t seq = 0;
    stamp(s, id, seq, welcome.bundles());
    welcome.state_seq(seq);
  });
  spdlog::info(
      "coordinator: applet '{}' in process '{}' announced itself ({} bundle(s) asked "
      "for)",
      hello.applet(), hello.process(), hello.wishes().size());
  send({hello.applet(), std::nullopt, std::move(welcome)});
  changed_();
}

void RemoteApplets::on_call(const SchedCall& call) {
  AppletId id = 0;
  {
    std::lock_guard lock(mutex_);
    const auto it = applets_.find(call.applet());
    if (it == applets_.end()) return;
    id = it->second.id;
  }
  SchedReply reply;
  reply.applet(call.applet());
  reply.session(call.session());
  reply.seq(call.seq());
  reply.coordinator(coordinator_id_);
  if (call.call() == "event_done") {
    // The applet applied an operator's event (its calls came before): also after its crash.
    {
      std::lock_guard lock(mutex_);
      const auto it = events_.find(call.event_id());
      if (it != events_.end()) it->second = call.error();
    }
    events_done_.notify_all();
    reply.ok(true);
    reply_writer_.write(reply);
    return;
  }
  if (!current(call.applet(), call.session())) {
    reply.ok(false);
    reply.kind("announce");
    reply.error(
        fmt::format("applet '{}' is not announced (its lease ran out, or the coordinator "
                    "restarted): it announces itself again",
                    call.applet()));
    reply_writer_.write(reply);
    return;
  }
  const auto& c = call.call();
  if (c == "crash") {  // the applet's code threw: it loses its bundles and nothing else
    {
      std::lock_guard lock(mutex_);
      applets_.at(call.applet()).crashed = true;
      applets_.at(call.applet()).present = false;
    }
    take_bundles(id);
    spdlog::warn("coordinator: applet '{}' crashed in its process: its bundles are released",
                 call.applet());
    reply.ok(true);
    reply_writer_.write(reply);
    changed_();
    return;
  }
  runtime_.with_scheduler([&](applets::Scheduler& s) {
    try {
      const BundleId b = s.model().bundle_id(id, call.bundle());
      if (c == "request") {
        s.request(b);
      } else if (c == "release") {
        s.release(b);
      } else if (c == "yield") {
        s.yield(b);
      } else if (c == "trigger") {
        s.trigger(b);
      } else if (c == "set_priority") {
        s.set_priority(b, call.priority());
      } else if (c == "set_deadline") {
        std::optional<applets::Deadline> d;
        if (call.has_deadline()) {
          d = applets::Deadline{std::chrono::milliseconds(call.t_early_ms()),
                                std::chrono::milliseconds(call.t_duration_ms()),
                                std::chrono::milliseconds(call.t_finish_ms())};
        }
        s.set_deadline(b, d);
      } else if (c == "negotiate") {
        applets::Negotiation answer;
        answer.min_needed = std::chrono::milliseconds(call.min_needed_ms());
        answer.max_needed = std::chrono::milliseconds(call.max_needed_ms());
        answer.accept = call.accept();
        const auto n = s.negotiate(b, answer);
        reply.kind(internal::notice_kind(n.kind));
        reply.until_ms(n.until.count());
      } else {
        throw std::invalid_argument(
            fmt::format("unknown call '{}' (calls: request, release, yield, trigger, set_priority, "
                        "set_deadline, negotiate, crash)",
                        c));
      }
      reply.ok(true);
    } catch (const std::invalid_argument& e) {
      reply.ok(false);
      reply.error(e.what());
    }
    std::uint64_t seq = 0;
    stamp(s, id, seq, reply.bundles());
    reply.state_seq(seq);
  });
  reply_writer_.write(reply);
  changed_();
}

void RemoteApplets::stamp(applets::Scheduler& s, AppletId id, std::uint64_t& seq,
                          std::vector<SchedBundleState>& states) {
  seq = ++state_seq_;
  states.clear();
  for (const BundleId b : s.model().applet(id).bundles) {
    SchedBundleState st;
    st.bundle(s.model().bundle(b).name);
    st.active(s.active(b));
    st.requested(s.requested(b));
    st.revoking(s.revoke_deadline(b).has_value());
    states.push_back(std::move(st));
  }
}

void RemoteApplets::send(Outgoing out) {
  std::lock_guard lock(mutex_);
  outgoing_.push_back(std::move(out));
  wake_.notify_all();
}

void RemoteApplets::check_leases() {
  std::vector<std::pair<std::string, AppletId>> lost;
  std::vector<std::string> gone;  // joined by their hello: removed, not just released
  {
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();
    for (auto& [name, a] : applets_) {
      if (a.present && now - a.last_beat > lease_) {
        a.present = false;
        if (a.joined) {
          gone.push_back(name);
        } else {
          lost.emplace_back(name, a.id);
        }
        spdlog::warn(
            "coordinator: applet '{}' in process '{}' missed its lease ({} ms): {}", name,
            a.process, lease_.count(),
            a.joined ? "it joined by its hello, so it is removed" : "its bundles are taken");
      }
    }
  }
  for (const auto& [name, id] : lost) take_bundles(id);
  for (const auto& name : gone) {
    if (membership_.leave) membership_.leave(name);
  }
  if (!gone.empty()) changed_();
  if (!lost.empty()) changed_();
}

void RemoteApplets::worker() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, kWorkerTick,
                   [&] { return stopping_ || !inbound_.empty() || !outgoing_.empty(); });
    if (stopping_) break;
    std::deque<std::function<void()>> inbound;
    inbound.swap(inbound_);
    lock.unlock();
    for (auto& f : inbound) {
      try {
        f();
      } catch (const std::exception& e) {
        spdlog::error("coordinator: an applet's message: {}", e.what());
      }
    }
    check_leases();
    lock.lock();
    std::deque<Outgoing> outgoing;
    outgoing.swap(outgoing_);
    lock.unlock();
    for (auto& out : outgoing) {
      auto& n = out.notice;
      n.applet(out.applet);
      n.coordinator(coordinator_id_);
      AppletId id = 0;
      bool known = true;
      {
        std::lock_guard l(mutex_);
        const auto it = applets_.find(out.applet);
        known = it != applets_.end();
        if (known) {
          const auto& a = it->second;
          id = a.id;
          if (out.notification) {
            if (!a.present) continue;  // it hears everything again when it announces itself
            n.session(a.session);
          }
        }
      }
      if (!known) {
        // Removed meanwhile (nothing to tell it), or an applet that beats unknown: asked to
        // announce itself (it may join by its hello).
        if (n.kind() == "announce") notice_writer_.write(n);
        continue;
      }
      runtime_.with_scheduler([&](applets::Scheduler& s) {
        if (out.notification) {
          const auto session = n.session();
          n = notice_of(s.model(), *out.notification);
          n.applet(out.applet);
          n.session(session);
          n.coordinator(coordinator_id_);
        }
        std::uint64_t seq = 0;
        stamp(s, id, seq, n.bundles());
        n.state_seq(seq);
      });
      notice_writer_.write(n);
    }
    lock.lock();
  }
}

void RemoteApplets::commands() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, kWorkerTick, [&] { return stopping_ || !commands_.empty(); });
    if (stopping_) break;
    std::deque<SchedCommand> batch;
    batch.swap(commands_);
    lock.unlock();
    for (const auto& c : batch) {
      SchedCommandReply out;
      out.applet(c.applet());
      out.session(c.session());
      out.seq(c.seq());
      {
        std::lock_guard l(mutex_);
        const auto it = applets_.find(c.applet());
        if (it == applets_.end()) continue;
      }
      if (!current(c.applet(), c.session())) {
        ConfigReply r;
        r.module_name(c.module_name());
        r.ok(false);
        r.error(
            fmt::format("applet '{}' is not announced (its lease ran out, or the coordinator "
                        "restarted): it holds nothing",
                        c.applet()));
        out.reply(r);
      } else {
        out.reply(c.trigger()
                      ? gateway_.trigger(c.applet(), c.service(), c.module_name(), c.kernel())
                      : gateway_.command(c.applet(), c.service(), c.module_name(), c.kernel(),
                                         c.command(), c.payload_type(), c.payload()));
      }
      command_reply_writer_.write(out);
    }
    lock.lock();
  }
}

}  // namespace oscar::coordinator
