#include "providers.hpp"

#include <spdlog/spdlog.h>

namespace oscar::coordinator {
namespace {
constexpr std::chrono::milliseconds kReplyTimeout{2000};
constexpr std::chrono::milliseconds kRetry{1000};
}  // namespace

Providers::Providers(const std::vector<ServiceSpec>& services, ConfigClient& client)
    : client_(client) {
  for (const auto& svc : services) add(svc);
}

void Providers::add(const ServiceSpec& service) {
  for (const auto& p : service.providers) {
    targets_[{p.module, p.kernel.empty() ? "*" : p.kernel}].push_back(service);
  }
}

void Providers::remove(const std::string& service) {
  for (auto it = targets_.begin(); it != targets_.end();) {
    std::erase_if(it->second, [&](const ServiceSpec& s) { return s.name == service; });
    if (!it->second.empty()) {
      ++it;
      continue;
    }
    applied_.erase(it->first);
    retry_at_.erase(it->first);
    it = targets_.erase(it);
  }
  recorded_.erase(service);
}

Providers::Desired Providers::desired(const Target& target,
                                      const std::set<std::string>& in_use) const {
  Desired d;
  bool idle_deactivates = false;
  bool granted = false;
  for (const auto& svc : targets_.at(target)) {
    if (!in_use.contains(svc.name)) continue;
    if (!granted && svc.activate) d.state = "activate:" + *svc.activate;
    granted = true;
    for (const auto& [name, value] : svc.granted_params) d.params.emplace(name, value);
  }
  for (const auto& svc : targets_.at(target)) {
    if (in_use.contains(svc.name)) continue;
    idle_deactivates = idle_deactivates || svc.idle_deactivates;
    for (const auto& [name, value] : svc.idle_params) d.params.emplace(name, value);
  }
  // In use, but granting configures no mode: the module's state is left be.
  if (!granted && idle_deactivates) d.state = "deactivate";
  return d;
}

std::string Providers::param_kernel(const Target& target) const {
  if (target.second != "*") return target.second;
  for (const auto& svc : targets_.at(target)) {
    for (const auto& p : svc.providers) {
      if (p.module == target.first && p.kernel.empty()) return p.param_kernel;  // its only one
    }
  }
  return {};
}

bool Providers::send_param(const Target& target, const std::string& name,
                           const std::string& value) {
  const auto& module = target.first;
  const auto kernel = param_kernel(target);
  try {
    const auto reply = client_.send(module, CMD_SET_PARAM, {kernel, name, value}, kReplyTimeout);
    if (!reply.ok()) {
      spdlog::warn("coordinator: set {}={} on {}/{} refused: {}", name, value, module, kernel,
                   reply.error());
      return false;
    }
    spdlog::info("coordinator: {}/{}: set {}={}", module, kernel, name, value);
    return true;
  } catch (const std::exception& e) {
    spdlog::warn("coordinator: set {}={} on {}/{}: {}", name, value, module, kernel, e.what());
    return false;
  }
}

bool Providers::send(const Target& target, const Desired& want, const Desired* had) {
  // Parameters first: a kernel that is activated starts with them.
  for (const auto& [name, value] : want.params) {
    if (had) {
      const auto it = had->params.find(name);
      if (it != had->params.end() && it->second == value) continue;
    }
    if (!send_param(target, name, value)) return false;
  }
  if (want.state.empty() || (had && had->state == want.state)) return true;
  return send_state(target, want.state);
}

bool Providers::send_state(const Target& target, const std::string& state) {
  const auto& [module, kernel] = target;
  try {
    ConfigReply reply;
    if (state == "deactivate") {
      reply = client_.send(module, CMD_DEACTIVATE, {kernel}, kReplyTimeout);
    } else {
      const auto mode = state.substr(std::string("activate:").size());
      std::vector<std::string> args{kernel};
      if (!mode.empty()) args.push_back(mode);
      reply = client_.send(module, CMD_ACTIVATE, args, kReplyTimeout);
    }
    if (!reply.ok()) {
      spdlog::warn("coordinator: {} {}/{} refused: {}", state, module, kernel, reply.error());
      return false;
    }
    spdlog::info("coordinator: {}/{}: {}", module, kernel,
                 state.ends_with(':') ? state.substr(0, state.size() - 1) : state);
    return true;
  } catch (const std::exception& e) {
    spdlog::warn("coordinator: {} {}/{}: {}", state, module, kernel, e.what());
    return false;
  }
}

void Providers::apply(const std::set<std::string>& in_use, const std::set<std::string>& unavailable,
                      const std::map<std::string, ModuleStatus>& modules) {
  // A service nobody holds any more starts afresh with its next holder; one that is away keeps
  // what its holder commanded.
  for (auto it = recorded_.begin(); it != recorded_.end();) {
    const bool keep = in_use.contains(it->first) || unavailable.contains(it->first);
    it = keep ? std::next(it) : recorded_.erase(it);
  }
  in_use_ = in_use;
  const auto now = Clock::now();
  for (const auto& [target, services] : targets_) {
    ModuleStatus status{true, 0};  // without the registry's word: try
    if (const auto it = modules.find(target.first); it != modules.end()) status = it->second;
    if (!status.running) {
      applied_.erase(target);  // configured again when it runs
      continue;
    }
    auto want = desired(target, in_use);
    const auto it = applied_.find(target);
    const bool restarted = it != applied_.end() && it->second.incarnation != status.incarnation;
    const Desired* had = it == applied_.end() || restarted ? nullptr : &it->second.desired;
    if (want.state.empty() && had) want.state = had->state;  // "leave it be": as it is
    if (had ? *had == want : want == Desired{}) continue;
    if (const auto r = retry_at_.find(target); r != retry_at_.end() && now < r->second) continue;
    if (!send(target, want, had)) {
      retry_at_[target] = now + kRetry;
      continue;
    }
    retry_at_.erase(target);
    applied_[target] = {want, status.incarnation};
    // Commands are recorded only while a service is held, and a held service's providers are
    // configured before its holder's first command goes out: so this is a restarted module (or
    // one that was not running): give it back what the holders of its services commanded.
    for (const auto& svc : services) {
      const auto rec = recorded_.find(svc.name);
      if (rec == recorded_.end()) continue;
      for (const auto& [key, r] : rec->second) {
        const auto& [module, kernel, command] = key;
        if (module != target.first) continue;
        try {
          const auto reply =
              client_.send_command(module, kernel, command, r.type, r.cdr, kReplyTimeout);
          spdlog::info("coordinator: {}: {}/{} {} re-applied after the restart: {}", svc.name,
                       module, kernel, command, reply.ok() ? "ok" : reply.error());
        } catch (const std::exception& e) {
          spdlog::warn("coordinator: re-applying {}/{} {}: {}", module, kernel, command, e.what());
        }
      }
    }
  }
}

bool Providers::ready(const std::string& service) const {
  for (const auto& [target, services] : targets_) {
    for (const auto& svc : services) {
      if (svc.name != service) continue;
      const auto want = desired(target, in_use_);
      if (want == Desired{}) continue;
      const auto it = applied_.find(target);
      if (it == applied_.end() || it->second.desired.params != want.params) return false;
      if (!want.state.empty() && it->second.desired.state != want.state) return false;
    }
  }
  return true;
}

void Providers::record(const std::string& service, const std::string& module,
                       const std::string& kernel, const std::string& command,
                       const std::string& type, std::vector<std::uint8_t> cdr) {
  recorded_[service][{module, kernel, command}] = Recorded{type, std::move(cdr)};
}

}  // namespace oscar::coordinator
