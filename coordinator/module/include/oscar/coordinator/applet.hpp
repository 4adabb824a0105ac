#pragma once
/// @file The applet API (docs/coordinator.md): an applet is a class with a main loop on the
/// applet scheduler's AppletContext (request and release bundles, use(), interrupts, negotiation)
/// that commands the modules of the services it holds through the coordinator. One line,
/// OSCAR_REGISTER_APPLET, makes it loadable, linked in or from a plugin
/// (`liboscar_applet_<type>.so` on the plugin path).

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <oscar/config.h>

#include "oscar/applets/applet_context.hpp"
#include "oscar/coordinator/cue_feed.hpp"
#include "oscar/idl_type_info.hpp"

namespace oscar::coordinator {

/// How an applet reaches the coordinator: in the coordinator's process the coordinator itself;
/// the same interface can carry an applet's calls from another process.
class AppletGateway {
 public:
  virtual ~AppletGateway() = default;
  /// Sends a request (CDR bytes of IDL `type`) to the command port `command` of `kernel` in
  /// `module`, which must provide `service`, on behalf of `applet`. Refused (ok() false, error()
  /// naming the current holder) unless the applet holds the service now.
  virtual ConfigReply command(const std::string& applet, const std::string& service,
                              const std::string& module, const std::string& kernel,
                              const std::string& command, const std::string& type,
                              std::vector<std::uint8_t> cdr) = 0;
  /// Triggers the single-step kernel `kernel` in `module` (the configuration flow's trigger: it
  /// runs once), which must provide `service`, on behalf of `applet`. Refused as command() is.
  virtual ConfigReply trigger(const std::string& applet, const std::string& service,
                              const std::string& module, const std::string& kernel) = 0;
  /// The name of a bundle (notifications name bundles by id).
  virtual std::string bundle_name(applets::BundleId bundle) const = 0;
};

/// What an applet's constructor gets: its name, its params from the system file, the gateway,
/// and the participant its cue feeds read from (none where applets are only made to be checked).
class AppletSetup {
 public:
  AppletSetup(std::string name, std::map<std::string, std::string> params, AppletGateway& gateway,
              DdsParticipant* participant = nullptr)
      : name_(std::move(name)),
        params_(std::move(params)),
        gateway_(gateway),
        participant_(participant) {}
  const std::string& name() const { return name_; }
  /// The `params:` of the applet, as text.
  const std::map<std::string, std::string>& params() const { return params_; }
  /// One parameter, or `fallback` if the system file does not set it.
  std::string param(const std::string& key, const std::string& fallback) const {
    const auto it = params_.find(key);
    return it == params_.end() ? fallback : it->second;
  }
  AppletGateway& gateway() const { return gateway_; }
  DdsParticipant* participant() const { return participant_; }

 private:
  std::string name_;
  std::map<std::string, std::string> params_;
  AppletGateway& gateway_;
  DdsParticipant* participant_;
};

/// The base of every applet (seed 000 §4.1, Abb. 4.12). The constructor only reads its params;
/// init() and step() run in the applet's own thread, which the coordinator starts; interrupts
/// run between steps. An applet whose code throws loses its bundles and nothing else.
class Applet {
 public:
  explicit Applet(AppletSetup& setup)
      : name_(setup.name()), gateway_(setup.gateway()), participant_(setup.participant()) {}
  virtual ~Applet() = default;
  Applet(const Applet&) = delete;
  Applet& operator=(const Applet&) = delete;

  /// Once, before the first step (e.g. request the bundles).
  virtual void init(applets::AppletContext& /*ctx*/) {}
  /// One step of the main loop, every period().
  virtual void step(applets::AppletContext& ctx) = 0;
  /// A notification from the scheduler (granted, revocation requested, negotiation reply,
  /// revoked by force, deadline overlap or expiry), between steps. Return true if handled;
  /// false leaves the default: a bundle whose revocation is requested is yielded at once.
  virtual bool on_interrupt(applets::AppletContext& /*ctx*/,
                            const applets::Notification& /*notification*/) {
    return false;
  }
  virtual std::chrono::milliseconds period() const { return std::chrono::milliseconds(10); }

  const std::string& name() const { return name_; }

 protected:
  /// Sends `request` to the command port `command` of `kernel` in `module`, a provider of
  /// `service`, through the coordinator, and returns the reply: ok() when the kernel accepted
  /// it; refused with the holder's name if this applet does not hold `service` now.
  template <IdlStruct T>
  ConfigReply command(const std::string& service, const std::string& module,
                      const std::string& kernel, const std::string& command, const T& request) {
    const auto& type = idl_type_info<T>();
    return gateway_.command(name_, service, module, kernel, command, type.name,
                            type.serialize(&request));
  }
  /// Triggers the single-step kernel `kernel` in `module`, a provider of `service`, through the
  /// coordinator: it runs once (its mode's trigger is `command`). Refused as command() is. (Not
  /// AppletContext::trigger, which raises a bundle's priority.)
  ConfigReply trigger(const std::string& service, const std::string& module,
                      const std::string& kernel) {
    return gateway_.trigger(name_, service, module, kernel);
  }
  /// The name of the bundle a notification is about.
  std::string bundle_name(const applets::Notification& n) const {
    return gateway_.bundle_name(n.bundle);
  }
  /// Starts reading the cues of output `address` ("kernel/channel") of any module: the feed
  /// holds the newest (CueFeed). Call it in init() (the constructor only reads params); the
  /// applet owns the feed until it is destroyed. Reading needs no service: cues are for anyone.
  /// @throws std::logic_error where the applet has no participant (made only to be checked).
  template <CueType T>
  const CueFeed<T>& cues(const std::string& address) {
    if (!participant_) {
      throw std::logic_error(
          "applet '" + name_ + "' reads cues of '" + address +
          "' where it does not run (call cues() in init(), not the constructor)");
    }
    auto feed = std::make_unique<CueFeed<T>>(*participant_, address);
    const auto& ref = *feed;
    feeds_.push_back(std::move(feed));
    return ref;
  }

 private:
  std::string name_;
  AppletGateway& gateway_;
  DdsParticipant* participant_;
  std::vector<std::unique_ptr<CueFeedBase>> feeds_;
};

namespace internal {
using AppletFactory = std::unique_ptr<Applet> (*)(AppletSetup&);
/// Registers an applet type; called by OSCAR_REGISTER_APPLET at load time. Returns true.
bool register_applet_type(const char* type, AppletFactory factory, const char* source_file);
template <class A>
std::unique_ptr<Applet> make_applet(AppletSetup& setup) {
  return std::make_unique<A>(setup);
}
}  // namespace internal

/// Makes an applet: a registered type, or one whose plugin (`liboscar_applet_<type>.so`) lies on
/// the search path (loaded then).
/// @throws std::runtime_error naming the type, the folders searched and the known types if there
///         is none, or with the loader's message if its plugin does not load.
std::unique_ptr<Applet> make_applet(const std::string& type, AppletSetup& setup,
                                    const std::vector<std::string>& search_path);

}  // namespace oscar::coordinator

#define OSCAR_INTERNAL_APPLET_CONCAT2(a, b) a##b
#define OSCAR_INTERNAL_APPLET_CONCAT(a, b) OSCAR_INTERNAL_APPLET_CONCAT2(a, b)
/// Makes CLASS loadable as applet type TYPE (one line, in the applet's .cpp).
#define OSCAR_REGISTER_APPLET(CLASS, TYPE)                                                         \
  static_assert(std::is_base_of_v<::oscar::coordinator::Applet, CLASS>,                            \
                #CLASS " must derive from oscar::coordinator::Applet to be registered");           \
  static_assert(std::is_constructible_v<CLASS, ::oscar::coordinator::AppletSetup&>,                \
                #CLASS " needs a constructor " #CLASS "(oscar::coordinator::AppletSetup& setup)"); \
  namespace {                                                                                      \
  [[maybe_unused]] const bool OSCAR_INTERNAL_APPLET_CONCAT(oscar_applet_registered_, __LINE__) =   \
      ::oscar::coordinator::internal::register_applet_type(                                        \
          TYPE, &::oscar::coordinator::internal::make_applet<CLASS>, __FILE__);                    \
  }
