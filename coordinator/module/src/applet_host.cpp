#include "oscar/coordinator/applet_host.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "oscar/applets/config.hpp"
#include "oscar/coordinator/applet_system.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "sched_wire.hpp"

namespace oscar::coordinator {
namespace {

using applets::AppletId;
using applets::BundleId;
using applets::Notification;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr milliseconds kSlice{20};              // waits are cut into slices that keep beating
constexpr milliseconds kHelloAgain{300};        // a hello not welcomed yet is sent again
constexpr milliseconds kCallTimeout{3000};      // a scheduler call's reply
constexpr milliseconds kCommandTimeout{10000};  // a command's reply (the coordinator may first
                                                // configure the providers, then the module answers)

ConfigReply refused(const std::string& module, const std::string& why) {
  ConfigReply r;
  r.module_name(module);
  r.ok(false);
  r.error(why);
  return r;
}

}  // namespace

class AppletHost::Impl final : public AppletGateway {
 public:
  Impl(const SystemSpec& system, DdsParticipant& participant, const std::vector<std::string>& names,
       std::string process, const std::vector<std::string>& plugin_path,
       const YAML::Node& joining = {}, const std::string& joining_file = {});
  ~Impl() override;
  void start();
  void stop();

  ConfigReply command(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel,
                      const std::string& command, const std::string& type,
                      std::vector<std::uint8_t> cdr) override;
  ConfigReply trigger(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel) override;
  std::string bundle_name(BundleId bundle) const override {
    return config_.model.bundle(bundle).name;
  }

 private:
  class Context;
  // Sends an applet's command or trigger to the coordinator and waits for its reply.
  ConfigReply send(SchedCommand command);
  struct Chain {  // a chain of negotiation rounds under way (applet thread only)
    std::shared_ptr<const applets::NegotiationRound> next;
    Clock::time_point round_started;
    std::uint64_t step = 0;
    int rounds = 0;
  };
  struct Settings {  // what the applet set on a bundle: announced again with its request
    std::optional<int> priority;
    std::optional<applets::Deadline> deadline;
  };
  struct Hosted {
    std::string name;
    std::string spec;  // a joining applet's entry (its hello carries it); empty: the file's
    AppletId id = 0;
    bool fail_stop = false;
    std::unique_ptr<Applet> applet;
    std::uint64_t session = 0;
    // Under the host's mutex:
    bool welcomed = false;
    bool crashed = false;  // its code threw: it says nothing more
    Clock::time_point last_hello{}, last_beat{};
    std::uint64_t coordinator = 0, state_seq = 0;
    std::map<std::string, SchedBundleState> bundles;  // the coordinator's view, latest
    std::map<std::string, bool> requested;            // what it asks for (true) and has set
    std::map<std::string, Settings> settings;
    std::deque<SchedNotice> notices;  // for the applet's thread
    std::uint64_t next_seq = 1;
    std::map<std::uint64_t, SchedReply> replies;
    std::map<std::uint64_t, SchedCommandReply> command_replies;
    std::condition_variable cv;
    // The applet's thread only:
    std::optional<BundleId> reacting_to_revocation;
    std::map<BundleId, Chain> negotiations;
    std::uint64_t steps = 0;
    std::thread thread;
  };

  Hosted& hosted(const std::string& applet);
  // Makes the applet `name` of type `type` (`where` names its entry in messages) and hosts it.
  void host(const std::string& name, const std::string& type, const std::string& where,
            const std::vector<std::string>& plugin_path, std::string spec);
  // Reads the applets that join the running system (AppletHost's `joining`) into the model.
  void read_joining(const YAML::Node& joining, const std::string& file,
                    const std::vector<std::string>& plugin_path);
  void applet_main(Hosted& h);
  // Sends a hello while not welcomed, else a beat when one is due (any thread of the applet).
  void pump(Hosted& h);
  // Waits until `ready` (under the lock) or `timeout`, beating meanwhile. False on timeout or stop.
  bool wait(Hosted& h, std::unique_lock<std::mutex>& lock, Clock::duration timeout,
            const std::function<bool()>& ready);
  void apply_state(Hosted& h, std::uint64_t coordinator, std::uint64_t seq,
                   const std::vector<SchedBundleState>& bundles);
  // A scheduler call; nullopt when the coordinator is not reachable now (the applet's wishes
  // are announced again when it is).
  std::optional<SchedReply> call(Hosted& h, SchedCall c);
  void on_notice(const SchedNotice& n);
  void on_reply(const SchedReply& r);
  void on_command_reply(const SchedCommandReply& r);
  Notification notification_of(const Hosted& h, const SchedNotice& n) const;
  std::optional<Notification> run_round(Context& ctx, Hosted& h, BundleId bundle,
                                        const applets::NegotiationRound& round);
  void run_negotiations(Context& ctx, Hosted& h);
  // Applies an operator's event (a notice of kind event) as the applet's own call and tells the
  // coordinator (event_done, with the refusal if any). False for "crash": the caller throws.
  bool apply_event(Context& ctx, Hosted& h, const SchedNotice& n);

  const SystemSpec& system_;
  applets::SystemConfig config_;
  std::string process_;
  milliseconds beat_every_;
  std::map<std::string, std::unique_ptr<Hosted>> hosted_;
  mutable std::mutex mutex_;
  bool stopping_ = false;
  bool started_ = false;
  TopicWriter<SchedHello, SchedHelloPubSubType> hello_writer_;
  TopicWriter<SchedBeat, SchedBeatPubSubType> beat_writer_;
  TopicWriter<SchedCall, SchedCallPubSubType> call_writer_;
  TopicWriter<SchedCommand, SchedCommandPubSubType> command_writer_;
  std::unique_ptr<TopicReader<SchedNotice, SchedNoticePubSubType>> notice_reader_;
  std::unique_ptr<TopicReader<SchedReply, SchedReplyPubSubType>> reply_reader_;
  std::unique_ptr<TopicReader<SchedCommandReply, SchedCommandReplyPubSubType>>
      command_reply_reader_;
};

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

AppletHost::Impl::Impl(const SystemSpec& system, DdsParticipant& participant,
                       const std::vector<std::string>& names, std::string process,
                       const std::vector<std::string>& plugin_path, const YAML::Node& joining,
                       const std::string& joining_file)
    : system_(system),
      config_(applet_system(system)),
      process_(std::move(process)),
      beat_every_(std::max(
          milliseconds(10),
          (system.coordinator ? system.coordinator->applet_lease : milliseconds(1500)) / 6)),
      hello_writer_(participant, topics::sched_hello()),
      beat_writer_(participant, topics::sched_beat()),
      call_writer_(participant, topics::sched_call()),
      command_writer_(participant, topics::sched_command()) {
  for (const auto& name : names) {
    const AppletSpec* spec = nullptr;
    if (system.coordinator) {
      for (const auto& a : system.coordinator->applets) {
        if (a.name == name) spec = &a;
      }
    }
    if (!spec) {
      throw std::invalid_argument(
          fmt::format("{}: no applet '{}' in the coordinator: section", system.file, name));
    }
    host(name, spec->type, spec->where, plugin_path, "");
  }
  if (joining && !joining.IsNull()) read_joining(joining, joining_file, plugin_path);
  notice_reader_ = std::make_unique<TopicReader<SchedNotice, SchedNoticePubSubType>>(
      participant, topics::sched_notice(),
      [this](const SchedNotice& n, const auto&) { on_notice(n); });
  reply_reader_ = std::make_unique<TopicReader<SchedReply, SchedReplyPubSubType>>(
      participant, topics::sched_reply(),
      [this](const SchedReply& r, const auto&) { on_reply(r); });
  command_reply_reader_ =
      std::make_unique<TopicReader<SchedCommandReply, SchedCommandReplyPubSubType>>(
          participant, topics::sched_command_reply(),
          [this](const SchedCommandReply& r, const auto&) { on_command_reply(r); });
}

void AppletHost::Impl::host(const std::string& name, const std::string& type,
                            const std::string& where, const std::vector<std::string>& plugin_path,
                            std::string spec) {
  auto h = std::make_unique<Hosted>();
  h->name = name;
  h->spec = std::move(spec);
  h->id = config_.model.applet_id(name);
  h->fail_stop = config_.model.applet(h->id).fail_stop;
  h->session = internal::fresh_id();
  AppletSetup setup(name, config_.applet_params[name], *this);
  try {
    h->applet = make_applet(type, setup, plugin_path);
  } catch (const std::exception& e) {
    throw std::invalid_argument(fmt::format("{}: applet '{}': {}", where, name, e.what()));
  }
  for (const BundleId b : config_.requested_at_start) {
    if (config_.model.bundle(b).applet == h->id) {
      h->requested[config_.model.bundle(b).name] = true;
    }
  }
  hosted_.emplace(name, std::move(h));
}

void AppletHost::Impl::read_joining(const YAML::Node& joining, const std::string& file,
                                    const std::vector<std::string>& plugin_path) {
  const auto addition = system_.parse_addition(joining, file, system_.services);
  if (!addition.services.empty() || addition.applets.empty()) {
    throw std::invalid_argument(fmt::format(
        "{}: joining applets are listed under applets: only (services are added with `oscar "
        "applets add`)",
        file));
  }
  for (const auto& a : addition.applets) {
    if (a.remote()) {
      throw std::invalid_argument(
          fmt::format("{}: applet '{}': a joining applet runs in this process; leave process: "
                      "and host: out",
                      a.where, a.name));
    }
    // Its bundles may use services added at run time: the coordinator checks them when it
    // adds the applet; here only the names count.
    for (const auto& b : a.node["bundles"]) {
      for (const auto& r : b["resources"]) {
        if (!r.IsMap() || !r["service"] || !r["service"].IsScalar()) continue;
        const auto service = r["service"].as<std::string>();
        if (!config_.model.find_service(service)) config_.model.add_service(service);
      }
    }
    for (const auto& p : a.node["provides"]) {
      if (p.IsScalar() && !config_.model.find_service(p.as<std::string>())) {
        config_.model.add_service(p.as<std::string>());
      }
    }
  }
  auto loaded = applets::load_addition(config_.model, scheduler_doc(addition), file);
  config_.model.add(loaded.addition);
  for (auto& [name, params] : loaded.applet_params) config_.applet_params[name] = params;
  for (const auto& [applet, bundle] : loaded.requested_at_start) {
    config_.requested_at_start.push_back(
        config_.model.bundle_id(config_.model.applet_id(applet), bundle));
  }
  for (const auto& a : addition.applets) {
    YAML::Node entry;
    entry["applets"].push_back(a.node);
    host(a.name, a.type, a.where, plugin_path, YAML::Dump(entry));
  }
}

AppletHost::Impl::~Impl() {
  stop();
  notice_reader_.reset();
  reply_reader_.reset();
  command_reply_reader_.reset();
}

void AppletHost::Impl::start() {
  std::lock_guard lock(mutex_);
  if (started_) return;
  started_ = true;
  for (auto& [name, h] : hosted_) {
    Hosted* p = h.get();
    p->thread = std::thread([this, p] { applet_main(*p); });
  }
}

void AppletHost::Impl::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (auto& [name, h] : hosted_) h->cv.notify_all();
  }
  for (auto& [name, h] : hosted_) {
    if (h->thread.joinable()) h->thread.join();
  }
}

AppletHost::Impl::Hosted& AppletHost::Impl::hosted(const std::string& applet) {
  const auto it = hosted_.find(applet);
  if (it == hosted_.end()) {
    throw std::invalid_argument(fmt::format("applet '{}' is not hosted here", applet));
  }
  return *it->second;
}

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

AppletHost::AppletHost(const SystemSpec& system, DdsParticipant& participant,
                       const std::vector<std::string>& applets, std::string process,
                       const std::vector<std::string>& plugin_path)
    : impl_(std::make_unique<Impl>(system, participant, applets, std::move(process), plugin_path)) {
}

AppletHost::AppletHost(const SystemSpec& system, DdsParticipant& participant,
                       const std::vector<std::string>& applets, const YAML::Node& joining,
                       const std::string& joining_file, std::string process,
                       const std::vector<std::string>& plugin_path)
    : impl_(std::make_unique<Impl>(system, participant, applets, std::move(process), plugin_path,
                                   joining, joining_file)) {}

AppletHost::~AppletHost() = default;

void AppletHost::start() { impl_->start(); }
void AppletHost::stop() { impl_->stop(); }

std::vector<std::string> AppletHost::applets_of(const SystemSpec& system,
                                                const std::string& process) {
  std::vector<std::string> names;
  if (!system.coordinator) return names;
  for (const auto& a : system.coordinator->applets) {
    if (a.process == process) names.push_back(a.name);
  }
  return names;
}

}  // namespace oscar::coordinator
