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

std::string Providers::desired(const Target& target, const std::set<std::string>& in_use) const {
  bool idle_deactivates = false;
  for (const auto& svc : targets_.at(target)) {
    if (in_use.contains(svc.name)) {
      if (svc.activate) return "activate:" + *svc.activate;
      return "";  // in use, but granting it configures nothing: leave the module be
    }
    idle_deactivates = idle_deactivates || svc.idle_deactivates;
  }
  return idle_deactivates ? "deactivate" : "";
}

bool Providers::send(const Target& target, const std::string& state) {
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
    spdlog::info("coordinator: {}/{}: {}", module, kernel, state);
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
    const auto want = desired(target, in_use);
    const auto it = applied_.find(target);
    const bool restarted = it != applied_.end() && it->second.incarnation != status.incarnation;
    if (want.empty() || (it != applied_.end() && it->second.state == want && !restarted)) continue;
    if (const auto r = retry_at_.find(target); r != retry_at_.end() && now < r->second) continue;
    if (!send(target, want)) {
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
      if (want.empty()) continue;
      const auto it = applied_.find(target);
      if (it == applied_.end() || it->second.state != want) return false;
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
