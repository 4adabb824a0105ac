// An applet that does what the world's events tell it (docs/coordinator.md): its bundles are
// requested, triggered and released through the coordinator's command port `applet` (a user's
// click, a battery running low, an appointment due: the events of seed 000 §5.3) or asked for at
// start (`requested: true`). It logs every grant and loss, so the log tells the plan's story.
// With `settle_priority: LEVEL` it changes a bundle's priority to LEVEL once the bundle is first
// granted: the main menu of §5.3 asks for the UI with high priority to be sure to get it, then
// takes the priority of the other applets. With `auto_yield: false` it keeps a bundle whose
// revocation is requested until an event tells it to yield or negotiate (or the wait limit
// passes): the applets of a scenario with `runner: {auto_yield: false}`. `period_ms` sets its
// loop's period (default 20): many idle applets of a benchmark wake seldom.
#include <spdlog/spdlog.h>
#include <oscar/applets/config.hpp>
#include <oscar/coordinator/applet.hpp>

#include <optional>
#include <set>
#include <stdexcept>

namespace {

using oscar::applets::Notification;

class EventApplet final : public oscar::coordinator::Applet {
 public:
  explicit EventApplet(oscar::coordinator::AppletSetup& setup) : Applet(setup) {
    const auto yield = setup.param("auto_yield", "true");
    if (yield != "true" && yield != "false") {
      throw std::invalid_argument("applet '" + name() +
                                  "': auto_yield must be true or false, not '" + yield + "'");
    }
    auto_yield_ = yield == "true";
    const auto period = setup.param("period_ms", "20");
    try {
      std::size_t used = 0;
      period_ = std::chrono::milliseconds(std::stoi(period, &used));
      if (used != period.size() || period_.count() < 1) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw std::invalid_argument("applet '" + name() +
                                  "': period_ms must be a whole number of ms >= 1, not '" + period +
                                  "'");
    }
    const auto level = setup.param("settle_priority", "");
    if (!level.empty()) {
      try {
        settle_ = oscar::applets::parse_priority(YAML::Load(level), "params");
      } catch (const std::exception& e) {
        throw std::invalid_argument("applet '" + name() + "': settle_priority: " + e.what());
      }
    }
  }

  void step(oscar::applets::AppletContext&) override {}

  bool on_interrupt(oscar::applets::AppletContext& ctx, const Notification& n) override {
    const auto bundle = bundle_name(n);
    switch (n.kind) {
      case Notification::Kind::kGranted:
        spdlog::info("applet {}: {} granted", name(), bundle);
        if (settle_ && settled_.insert(bundle).second) ctx.set_priority(bundle, *settle_);
        return true;
      case Notification::Kind::kRevokedByForce:
        spdlog::info("applet {}: {} revoked", name(), bundle);
        return true;
      case Notification::Kind::kRevokeRequested:
        if (!auto_yield_) {
          spdlog::info("applet {}: {} is to be given back; it keeps it for now", name(), bundle);
          return true;
        }
        spdlog::info("applet {}: {} yielded", name(), bundle);
        return false;  // the default: yield at once
      default:
        return false;
    }
  }

  std::chrono::milliseconds period() const override { return period_; }

 private:
  bool auto_yield_ = true;
  std::chrono::milliseconds period_{20};
  std::optional<int> settle_;
  std::set<std::string> settled_;  // bundles whose priority it has settled
};

}  // namespace

OSCAR_REGISTER_APPLET(EventApplet, "event_applet")
