// The coordinator told of services and applets as they come and go (seed 000 §4.1.1; docs/
// coordinator.md, "Adding and removing at run time"): added by an operator (the command port
// `applet`, `oscar applets add`) or by the hello of an applet joining from another process,
// removed by an operator or when a joined applet's lease runs out.
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "kernel_wishes.hpp"
#include "oscar/coordinator/applet_system.hpp"
#include "oscar/coordinator/coordinator.hpp"
#include "providers.hpp"
#include "remote_applets.hpp"

namespace oscar::coordinator {
namespace {

std::vector<std::string> names_of(const SystemAddition& addition) {
  std::vector<std::string> out;
  for (const auto& s : addition.services) out.push_back("service " + s.name);
  for (const auto& a : addition.applets) out.push_back("applet " + a.name);
  return out;
}

}  // namespace

void Coordinator::add_locked(const SystemAddition& addition, const YAML::Node& /*root*/,
                             const std::string& name, const std::string& remote) {
  for (const auto& a : addition.applets) {
    if (remote.empty() && a.remote()) {
      throw std::invalid_argument(fmt::format(
          "{}: applet '{}': process: and host: belong in the system file; an applet added here "
          "runs in the coordinator's process (one in a process of its own joins from there: "
          "oscar-applet SYSTEM --applets FILE)",
          a.where, a.name));
    }
  }
  applets::LoadedAddition loaded;
  const auto doc = scheduler_doc(addition);
  runtime_->with_scheduler(
      [&](applets::Scheduler& s) { loaded = applets::load_addition(s.model(), doc, name); });
  // Made before anything changes: an applet that cannot be made refuses the whole addition.
  std::vector<std::unique_ptr<Applet>> made;
  std::map<std::string, applets::AppletRunner> runners;
  for (const auto& a : addition.applets) {
    if (!remote.empty()) {
      runners[a.name] = applets::AppletRunner{std::nullopt, remote_->forwarder(a.name)};
      made.emplace_back();
      continue;
    }
    AppletSetup setup(a.name, loaded.applet_params[a.name], *this, &participant_);
    try {
      made.push_back(make_applet(a.type, setup, plugin_path_));
    } catch (const std::exception& e) {
      throw std::invalid_argument(fmt::format("{}: applet '{}': {}", a.where, a.name, e.what()));
    }
    runners[a.name] = applets::AppletRunner{code_of(made.back().get()), nullptr};
  }
  const auto ids = runtime_->add(loaded.addition, std::move(runners));
  for (std::size_t i = 0; i < ids.applets.size(); ++i) {
    if (applets_.size() <= ids.applets[i]) applets_.resize(ids.applets[i] + 1);
    applets_[ids.applets[i]] = std::move(made[i]);
  }
  if (!remote.empty()) {
    for (std::size_t i = 0; i < ids.applets.size(); ++i) {
      remote_->adopt(addition.applets[i].name, ids.applets[i], remote);
    }
  }
  // Who provides what, as the plan shows it: the modules of the added services, the applets.
  std::vector<std::pair<applets::ServiceId, std::string>> provided;
  runtime_->with_scheduler([&](applets::Scheduler& s) {
    for (const auto id : ids.applets) {
      for (const auto p : s.model().applet(id).provides) {
        provided.emplace_back(p, "applet:" + s.model().applet(id).name);
      }
    }
  });
  {
    std::lock_guard lock(services_mutex_);
    for (std::size_t i = 0; i < addition.services.size(); ++i) {
      services_.push_back(addition.services[i]);
      if (providers_of_.size() <= ids.services[i]) providers_of_.resize(ids.services[i] + 1);
      auto& names = providers_of_[ids.services[i]];
      names.clear();
      for (const auto& p : addition.services[i].providers) names.push_back(p.text());
    }
    for (const auto& [id, text] : provided) {
      if (providers_of_.size() <= id) providers_of_.resize(id + 1);
      providers_of_[id] = {text};
    }
  }
  {
    std::lock_guard reconciling(reconcile_mutex_);
    for (const auto& svc : addition.services) providers_->add(svc);
  }
  // `requested: true` asks at once; an applet in another process asks in its hello.
  if (remote.empty()) {
    runtime_->with_scheduler([&](applets::Scheduler& s) {
      for (const auto& [applet, bundle] : loaded.requested_at_start) {
        s.request(s.model().bundle_id(s.model().applet_id(applet), bundle));
      }
    });
  }
  spdlog::info("coordinator: added {} ({})", fmt::join(names_of(addition), ", "), name);
  wake();
}

SystemAddition Coordinator::read_addition(const YAML::Node& root, const std::string& name) {
  std::vector<ServiceSpec> now;
  {
    std::lock_guard lock(services_mutex_);
    now = services_;
  }
  return system_.parse_addition(root, name, now);
}

std::optional<std::string> Coordinator::add_spec(const std::string& spec, const std::string& name) {
  try {
    std::lock_guard changing(change_mutex_);
    const auto root = applets::parse_yaml(spec, name);
    const auto addition = read_addition(root, name);
    add_locked(addition, root, name, "");
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

std::optional<std::string> Coordinator::join(const std::string& applet, const std::string& process,
                                             const std::string& spec) {
  const auto name = fmt::format("the hello of applet '{}'", applet);
  try {
    std::lock_guard changing(change_mutex_);
    const auto root = applets::parse_yaml(spec, name);
    const auto addition = read_addition(root, name);
    if (!addition.services.empty() || addition.applets.size() != 1 ||
        addition.applets.front().name != applet) {
      throw std::invalid_argument(fmt::format(
          "{}: the spec of a joining applet names that applet only (applets: [{{name: {}, "
          "...}}]); services are added with `oscar applets add`",
          name, applet));
    }
    add_locked(addition, root, name, process);
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

std::optional<std::string> Coordinator::remove_applet(const std::string& applet) {
  return remove_applet(applet, true);
}

std::optional<std::string> Coordinator::remove_applet(const std::string& applet, bool by_operator) {
  try {
    std::lock_guard changing(change_mutex_);
    applets::AppletId id = 0;
    runtime_->with_scheduler([&](applets::Scheduler& s) { id = s.model().applet_id(applet); });
    const bool joined = remote_->joined(applet);
    if (!wishes_->module_of(applet).empty()) {
      throw std::invalid_argument(fmt::format(
          "'{}' is a kernel's wishes, which the system file's coordinator: wishes: declares; "
          "remove them there",
          applet));
    }
    if (remote_->remote(applet) && !joined) {
      throw std::invalid_argument(fmt::format(
          "applet '{}' runs in a process the system file starts, which would announce it "
          "again; remove it from the system file instead",
          applet));
    }
    runtime_->remove_applet(applet);  // its thread ends here
    // Removed by an operator, a joined applet's process may not join again until it restarts;
    // one whose lease ran out may, when it is heard again.
    remote_->forget(applet, by_operator);
    if (id < applets_.size()) applets_[id].reset();
    {
      std::lock_guard lock(services_mutex_);
      for (auto& names : providers_of_) {
        std::erase(names, "applet:" + applet);
      }
    }
    spdlog::info("coordinator: removed applet {}{}", applet,
                 by_operator ? "" : " (its process is not heard from)");
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  wake();
  return std::nullopt;
}

std::optional<std::string> Coordinator::remove_service(const std::string& service) {
  try {
    std::lock_guard changing(change_mutex_);
    runtime_->remove_service(service);  // refused while anything uses it
    {
      std::lock_guard lock(services_mutex_);
      std::erase_if(services_, [&](const ServiceSpec& s) { return s.name == service; });
    }
    std::lock_guard reconciling(reconcile_mutex_);
    providers_->remove(service);
    spdlog::info("coordinator: removed service {}", service);
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  wake();
  return std::nullopt;
}

}  // namespace oscar::coordinator
