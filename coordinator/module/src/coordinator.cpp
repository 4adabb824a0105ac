#include "oscar/coordinator/coordinator.hpp"

#include <algorithm>
#include <functional>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "kernel_wishes.hpp"
#include "oscar/coordinator/applet_system.hpp"
#include "oscar/time.hpp"
#include "providers.hpp"
#include "remote_applets.hpp"
#include "sched_wire.hpp"

namespace oscar::coordinator {
namespace {

using applets::BundleId;
using applets::ServiceId;
constexpr std::chrono::milliseconds kTick{20};
constexpr std::chrono::milliseconds kReadyWait{3000};

ConfigReply refused(const std::string& module, const std::string& why) {
  ConfigReply r;
  r.module_name(module);
  r.ok(false);
  r.error(why);
  return r;
}

std::vector<std::string> sorted(const std::set<std::string>& s) { return {s.begin(), s.end()}; }

}  // namespace

struct Coordinator::Snapshot {
  std::set<std::string> in_use;  // services granted, directly or as what a granted one needs
  AppletPlan plan;
};

Coordinator::Coordinator(const SystemSpec& system, DdsParticipant& participant,
                         const std::vector<std::string>& plugin_path)
    : system_(system),
      participant_(participant),
      plugin_path_(plugin_path),
      config_(applet_system(system)),
      services_(system.services),
      plan_writer_(participant, topics::applet_plan()) {
  runtime_ = std::make_unique<applets::Runtime>(config_.model, config_.options);
  applets_.resize(config_.model.applets().size());
  if (system.coordinator) {
    for (const auto& a : system.coordinator->applets) {
      if (a.remote()) continue;  // made and run in its own process
      AppletSetup setup(a.name, config_.applet_params[a.name], *this, &participant);
      try {
        applets_.at(config_.model.applet_id(a.name)) = make_applet(a.type, setup, plugin_path);
      } catch (const std::exception& e) {
        throw std::invalid_argument(fmt::format("{}: applet '{}': {}", a.where, a.name, e.what()));
      }
    }
  }
  for (std::size_t id = 0; id < applets_.size(); ++id) {
    Applet* a = applets_[id].get();
    if (!a) continue;  // runs in another process (or a service applet without code of its own)
    runtime_->set_code(a->name(), code_of(a));
  }
  // Who provides each service, as the plan shows it.
  providers_of_.resize(config_.model.services().size());
  for (const auto& svc : system.services) {
    auto& names = providers_of_.at(config_.model.service_id(svc.name));
    for (const auto& p : svc.providers) names.push_back(p.text());
  }
  for (const auto& a : config_.model.applets()) {
    for (const ServiceId s : a.provides) providers_of_.at(s).push_back("applet:" + a.name);
  }
  RemoteApplets::Membership membership;
  membership.join = [this](const std::string& applet, const std::string& process,
                           const std::string& spec) { return join(applet, process, spec); };
  membership.leave = [this](const std::string& applet) {
    if (const auto error = remove_applet(applet, false)) {
      spdlog::warn("coordinator: removing applet '{}': {}", applet, *error);
    }
  };
  remote_ = std::make_unique<RemoteApplets>(
      system, *runtime_, *this, participant, [this] { wake(); }, std::move(membership));
  wishes_ = std::make_unique<KernelWishes>(system, *runtime_, participant, [this] { wake(); });
  client_ = std::make_unique<ConfigClient>(participant, "coordinator");
  providers_ = std::make_unique<Providers>(system.services, *client_);
  system_reader_ = std::make_unique<TopicReader<SystemState, SystemStatePubSubType>>(
      participant, topics::system_state(),
      [this](const SystemState& s, const auto&) { on_system_state(s); });
}

applets::AppletCode Coordinator::code_of(Applet* a) {
  applets::AppletCode code;
  code.init = [a](applets::AppletContext& ctx) { a->init(ctx); };
  code.step = [a](applets::AppletContext& ctx) { a->step(ctx); };
  code.on_interrupt = [a, this](applets::AppletContext& ctx, const applets::Notification& n) {
    if (!a->on_interrupt(ctx, n) && n.kind == applets::Notification::Kind::kRevokeRequested) {
      ctx.yield(bundle_name(n.bundle));
    }
  };
  code.period = a->period();
  return code;
}

Coordinator::~Coordinator() {
  stop();
  system_reader_.reset();  // no callback into a half-destroyed object
  remote_.reset();
  wishes_.reset();
}

void Coordinator::wake() {
  std::lock_guard lock(mutex_);
  woken_ = true;
  wake_.notify_all();
}

void Coordinator::start() {
  {
    std::lock_guard lock(mutex_);
    if (started_) return;
    started_ = true;
  }
  runtime_->start();
  runtime_->with_scheduler([&](applets::Scheduler& s) {
    for (const BundleId b : config_.requested_at_start) {
      // A remote applet asks for its bundles itself when it announces itself.
      if (!remote_->remote(s.model().applet(s.model().bundle(b).applet).name)) s.request(b);
    }
  });
  remote_->start();
  thread_ = std::thread([this] { loop(); });
}

void Coordinator::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  remote_->stop();
  runtime_->stop();
}

void Coordinator::loop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    try {
      std::lock_guard reconciling(reconcile_mutex_);
      reconcile();
    } catch (const std::exception& e) {
      spdlog::error("coordinator: {}", e.what());
    }
    lock.lock();
    // Applets' own requests and releases are seen at the next tick; events and the registry's
    // reports wake the loop at once.
    wake_.wait_for(lock, kTick, [&] { return stopping_ || woken_; });
    woken_ = false;
  }
}

void Coordinator::on_system_state(const SystemState& state) {
  {
    std::lock_guard lock(mutex_);
    for (const auto& m : state.modules()) {
      auto& known = modules_[m.name()];
      known.running = m.status() == "running";
      known.incarnation = m.incarnation();
      known.ran = known.ran || known.running;
    }
    woken_ = true;
  }
  wake_.notify_all();
}

Coordinator::Snapshot Coordinator::snapshot() {
  Snapshot snap;
  auto& plan = snap.plan;
  plan.system(system_.name);
  std::vector<std::string> applet_names;  // the applets there are now, by id
  std::vector<char> holding, waiting;
  std::vector<std::vector<std::string>> granted;  // per applet: its bundles usable now
  runtime_->with_scheduler([&](applets::Scheduler& s) {
    const auto& m = s.model();
    holding.assign(m.applets().size(), 0);
    waiting.assign(m.applets().size(), 0);
    granted.assign(m.applets().size(), {});
    std::vector<char> used(m.services().size());
    std::function<void(ServiceId)> mark = [&](ServiceId id) {
      if (used[id]) return;
      used[id] = 1;
      for (const auto& u : m.needs(id)) mark(u.service);
    };
    std::vector<std::set<std::string>> holders(used.size()), waiters(used.size());
    for (BundleId b = 0; b < m.bundles().size(); ++b) {
      const bool active = s.active(b);
      if (!active && !s.requested(b)) continue;
      const auto applet = m.bundle(b).applet;
      (active ? holding : waiting)[applet] = 1;
      if (active) granted[applet].push_back(m.bundle(b).name);
      for (const auto& u : m.bundle_uses(b)) {
        if (active) mark(u.service);
        (active ? holders : waiters)[u.service].insert(m.applet(applet).name);
      }
    }
    std::lock_guard lock(services_mutex_);
    for (ServiceId id = 0; id < used.size(); ++id) {
      const auto& svc = m.service(id);
      if (svc.removed) continue;
      if (used[id]) snap.in_use.insert(svc.name);
      ServicePlan p;
      p.name(svc.name);
      p.access(svc.exclusive_only ? "exclusive" : "shared");
      p.holders(sorted(holders[id]));
      std::set<std::string> w;
      std::set_difference(waiters[id].begin(), waiters[id].end(), holders[id].begin(),
                          holders[id].end(), std::inserter(w, w.end()));
      p.waiting(sorted(w));
      p.available(s.available(id));
      p.plan(s.holder(id));
      p.active(s.active_holder(id));
      for (const auto& u : m.needs(id)) p.needs().push_back(m.service(u.service).name);
      if (id < providers_of_.size()) p.providers(providers_of_[id]);
      plan.services().push_back(std::move(p));
    }
    for (const auto& a : m.applets()) applet_names.push_back(a.removed ? "" : a.name);
    plan.plans(s.plans_computed());
    plan.plan_us(std::chrono::duration<double, std::micro>(s.last_plan_time()).count());
  });
  for (std::size_t id = 0; id < applet_names.size(); ++id) {
    if (applet_names[id].empty()) continue;  // removed
    AppletEntry e;
    e.name(applet_names[id]);
    e.process(SystemSpec::kCoordinatorModule);
    e.granted(std::move(granted[id]));
    std::optional<std::string> state;
    try {
      if (const auto module = wishes_->module_of(e.name()); !module.empty()) {
        e.process(module);  // a kernel's wishes
      } else if (remote_->remote(e.name())) {
        auto seen = remote_->seen(e.name());
        e.process(seen.process);
        state = seen.state;
      } else if (runtime_->crashed(e.name())) {
        state = "crashed";
      }
    } catch (const std::exception&) {
      continue;  // removed since the plan above was taken
    }
    e.state(state ? *state : holding[id] ? "holding" : waiting[id] ? "waiting" : "idle");
    plan.applets().push_back(std::move(e));
  }
  return snap;
}

void Coordinator::reconcile() {
  std::map<std::string, Providers::ModuleStatus> modules;
  std::set<std::string> down;  // ran, and does not run now (failed, restarting)
  {
    std::lock_guard lock(mutex_);
    for (const auto& [name, m] : modules_) {
      modules[name] = {m.running, m.incarnation};
      if (m.ran && !m.running) down.insert(name);
    }
  }
  wishes_->apply(modules);  // what kernels ask for now (nothing of a module that is down)
  // A service whose provider module is down is unavailable: its holders lose it and keep their
  // request; it is granted again once the module runs. (A module still starting at boot is not
  // down: its service can be granted, and the providers are configured once it runs.)
  std::set<std::string> unavailable;
  std::vector<ServiceSpec> services;
  {
    std::lock_guard lock(services_mutex_);
    services = services_;
  }
  for (const auto& svc : services) {
    for (const auto& p : svc.providers) {
      if (down.contains(p.module)) unavailable.insert(svc.name);
    }
  }
  runtime_->with_scheduler([&](applets::Scheduler& s) {
    for (const auto& svc : services) {
      if (svc.providers.empty()) continue;  // an applet provides it: no module can go down
      const auto found = s.model().find_service(svc.name);
      if (!found) continue;  // removed meanwhile
      const auto id = *found;
      const bool available = !unavailable.contains(svc.name);
      if (s.available(id) == available) continue;
      spdlog::warn("coordinator: service {} is {}", svc.name,
                   available ? "available again" : "unavailable: a module providing it is down");
      s.set_available(id, available);
    }
  });
  auto snap = snapshot();
  providers_->apply(snap.in_use, unavailable, modules);
  AppletPlan unstamped = snap.plan;
  if (!published_any_ || !(unstamped == published_)) {
    published_ = unstamped;
    published_any_ = true;
    snap.plan.stamp_ns(static_cast<unsigned long long>(wall_now()));
    runtime_->with_scheduler([&](applets::Scheduler& s) { snap.plan.clock_ms(s.now().count()); });
    plan_writer_.write(snap.plan);
  }
}

AppletPlan Coordinator::plan() { return snapshot().plan; }

std::optional<std::string> Coordinator::apply_event(const AppletEvent& e) {
  if (e.event() == "add") {
    return add_spec(e.spec(), e.spec_name().empty() ? std::string("spec") : e.spec_name());
  }
  if (e.event() == "remove") {
    if (!e.service().empty() && !e.applet().empty()) {
      return "event 'remove' names an applet or a service, not both";
    }
    if (!e.service().empty()) return remove_service(e.service());
    if (!e.applet().empty()) return remove_applet(e.applet());
    return std::string(
        "event 'remove' needs the applet (applet) or the service (service) to remove");
  }
  // An applet in another process applies the event as its own call (it keeps what it asks for,
  // and announces it again after a restart of either side).
  if (remote_->remote(e.applet())) return remote_->event(e);
  if (!wishes_->module_of(e.applet()).empty()) {
    return fmt::format("'{}' is a kernel's wishes: its kernel asks for them and drops them",
                       e.applet());
  }
  std::optional<std::string> error;
  runtime_->with_scheduler([&](applets::Scheduler& s) {
    try {
      const auto& m = s.model();
      const auto b = m.bundle_id(m.applet_id(e.applet()), e.bundle());
      const auto& what = e.event();
      if (what == "request") {
        s.request(b);
      } else if (what == "release") {
        s.release(b);
      } else if (what == "trigger") {
        s.trigger(b);
      } else if (what == "yield") {
        s.yield(b);
      } else if (what == "set_priority") {
        s.set_priority(b, e.priority());
      } else if (what == "set_deadline") {
        std::optional<applets::Deadline> d;
        if (e.has_deadline()) {
          d = applets::Deadline{std::chrono::milliseconds(e.t_early_ms()),
                                std::chrono::milliseconds(e.t_duration_ms()),
                                std::chrono::milliseconds(e.t_finish_ms())};
        }
        s.set_deadline(b, d);
      } else if (what == "negotiate") {
        applets::Negotiation answer;
        answer.min_needed = std::chrono::milliseconds(e.min_ms());
        answer.max_needed = std::chrono::milliseconds(e.max_ms());
        answer.accept = e.accept();
        s.negotiate(b, answer);
      } else if (what == "crash") {
        error = fmt::format(
            "event 'crash' is for applets in a process of their own (applet '{}' runs in the "
            "coordinator's process, which it would end)",
            e.applet());
      } else {
        error = fmt::format("unknown event '{}' (events: {})", what, internal::kAppletEvents);
      }
    } catch (const std::invalid_argument& x) {
      error = x.what();
    }
  });
  if (!error) {
    std::lock_guard lock(mutex_);
    woken_ = true;
    wake_.notify_all();
  }
  return error;
}

std::string Coordinator::bundle_name(applets::BundleId bundle) const {
  return runtime_->bundle_name(bundle);
}

std::optional<ConfigReply> Coordinator::refuse_unless_held(const std::string& applet,
                                                           const std::string& service,
                                                           const std::string& module,
                                                           const std::string& kernel) {
  std::optional<ServiceSpec> svc;
  {
    std::lock_guard lock(services_mutex_);
    for (const auto& x : services_) {
      if (x.name == service) svc = x;
    }
  }
  if (!svc) return refused(module, fmt::format("no service '{}' in the system", service));
  const bool provides = std::any_of(svc->providers.begin(), svc->providers.end(), [&](auto& p) {
    return p.module == module && (p.kernel.empty() || p.kernel == kernel);
  });
  if (!provides) {
    std::vector<std::string> names;
    for (const auto& p : svc->providers) names.push_back(p.text());
    return refused(module, fmt::format("{}/{} does not provide service '{}' (its providers: {})",
                                       module, kernel, service, fmt::join(names, ", ")));
  }
  bool holds = false;
  std::string holder;
  try {
    runtime_->with_scheduler([&](applets::Scheduler& s) {
      const auto& m = s.model();
      const auto id = m.service_id(service);
      for (const BundleId b : m.applet(m.applet_id(applet)).bundles) {
        if (!s.active(b)) continue;
        for (const auto& u : m.bundle_uses(b)) holds = holds || u.service == id;
      }
      holder = s.active_holder(id);
    });
  } catch (const std::invalid_argument& e) {  // removed meanwhile
    return refused(module, e.what());
  }
  if (holds) return std::nullopt;
  return refused(module, fmt::format("applet '{}' does not hold service '{}': {}", applet, service,
                                     holder == "none" ? std::string("nobody holds it now")
                                                      : fmt::format("it is held by '{}'", holder)));
}

std::optional<ConfigReply> Coordinator::await_providers(const std::string& service,
                                                        const std::string& module) {
  // The holder may be quicker than the loop: configure the providers first (a deactivated
  // kernel refuses commands and triggers).
  const auto until = std::chrono::steady_clock::now() + kReadyWait;
  reconcile();
  while (!providers_->ready(service)) {
    if (std::chrono::steady_clock::now() > until) {
      return refused(module, fmt::format("the providers of service '{}' could not be configured "
                                         "for its holder (see the coordinator's log)",
                                         service));
    }
    std::this_thread::sleep_for(kTick);
    reconcile();
  }
  return std::nullopt;
}

ConfigReply Coordinator::command(const std::string& applet, const std::string& service,
                                 const std::string& module, const std::string& kernel,
                                 const std::string& command, const std::string& type,
                                 std::vector<std::uint8_t> cdr) {
  if (auto refusal = refuse_unless_held(applet, service, module, kernel)) return *refusal;
  std::lock_guard reconciling(reconcile_mutex_);
  if (auto refusal = await_providers(service, module)) return *refusal;
  try {
    auto reply = client_->send_command(module, kernel, command, type, cdr);
    if (reply.ok()) providers_->record(service, module, kernel, command, type, std::move(cdr));
    return reply;
  } catch (const std::exception& e) {
    return refused(module, e.what());
  }
}

ConfigReply Coordinator::trigger(const std::string& applet, const std::string& service,
                                 const std::string& module, const std::string& kernel) {
  if (auto refusal = refuse_unless_held(applet, service, module, kernel)) return *refusal;
  {
    std::lock_guard reconciling(reconcile_mutex_);
    if (auto refusal = await_providers(service, module)) return *refusal;
  }
  // Sent without the lock: a trigger is not recorded (a restarted module gets configuration
  // back, not past cycles), so triggers of modules on different hosts may go out side by side.
  try {
    return client_->send(module, CMD_TRIGGER, {kernel});
  } catch (const std::exception& e) {
    return refused(module, e.what());
  }
}

}  // namespace oscar::coordinator
