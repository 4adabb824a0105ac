#pragma once
// The provider modules of the services (not installed): configures them as the services they
// provide are granted or idle, and gives a restarted module back what the holders commanded.

#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "oscar/config_client.hpp"
#include "oscar/registry/system_spec.hpp"

namespace oscar::coordinator {

class Providers {
 public:
  /// What the registry says of a module: running or not, and which start of it this is.
  struct ModuleStatus {
    bool running = false;
    unsigned long incarnation = 0;
  };

  /// The providers of `services` (the system file's, at first).
  Providers(const std::vector<ServiceSpec>& services, ConfigClient& client);

  /// A service added at run time: its providers are configured from now on as the file's are.
  void add(const ServiceSpec& service);
  /// A service removed at run time (nobody holds it): its providers are not configured for it
  /// any more.
  void remove(const std::string& service);

  /// Configures every provider as `in_use` (service names) asks: the parameters of `granted:
  /// {set: ...}` of its granted services and of `idle: {set: ...}` of its idle ones (a granted
  /// service's value wins, then the first in the file), then activate for a granted service
  /// with `granted: {activate: MODE}`, deactivate when all services of a provider are idle and
  /// one says `idle: deactivate`. A module the registry reports not running is left until it
  /// runs again; a module that runs with a new incarnation (restarted) is configured again, and
  /// gets the commands its services' holders sent (kept while a service is `unavailable`, for
  /// its holder to get back). What fails is tried again after a second.
  void apply(const std::set<std::string>& in_use, const std::set<std::string>& unavailable,
             const std::map<std::string, ModuleStatus>& modules);
  /// Whether every provider of `service` is configured as granted (or needs nothing).
  bool ready(const std::string& service) const;
  /// Remembers an accepted command to a provider of `service`, to give it back after a restart.
  void record(const std::string& service, const std::string& module, const std::string& kernel,
              const std::string& command, const std::string& type, std::vector<std::uint8_t> cdr);

 private:
  using Clock = std::chrono::steady_clock;
  using Target = std::pair<std::string, std::string>;  // module, kernel ("*": all of them)
  struct Desired {
    std::string state;                          // "activate:<mode>", "deactivate", "": leave it
    std::map<std::string, std::string> params;  // parameter -> value
    bool operator==(const Desired&) const = default;
  };
  struct Applied {
    Desired desired;
    unsigned long incarnation = 0;
  };
  struct Recorded {
    std::string type;
    std::vector<std::uint8_t> cdr;
  };
  Desired desired(const Target& target, const std::set<std::string>& in_use) const;
  // Sends what `want` has and `had` (nullptr: nothing known) has not; true if all was accepted.
  bool send(const Target& target, const Desired& want, const Desired* had);
  bool send_state(const Target& target, const std::string& state);
  bool send_param(const Target& target, const std::string& name, const std::string& value);
  // The kernel a parameter of `target` goes to: its own, or the module's only one.
  std::string param_kernel(const Target& target) const;

  ConfigClient& client_;
  std::map<Target, std::vector<ServiceSpec>> targets_;
  std::map<Target, Applied> applied_;
  std::map<Target, Clock::time_point> retry_at_;
  // Per service: the last accepted command per (module, kernel, command).
  std::map<std::string, std::map<std::tuple<std::string, std::string, std::string>, Recorded>>
      recorded_;
  std::set<std::string> in_use_;
};

}  // namespace oscar::coordinator
