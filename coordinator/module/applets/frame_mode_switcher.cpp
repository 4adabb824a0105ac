// An applet that holds a camera service and switches the framegrabber's frame mode by its
// command port `frame_mode` (seed 004 §4.2: MARVIN's coordinator switches between quarter and
// half frames), see docs/coordinator.md.
#include <spdlog/spdlog.h>
#include <oscar/command_types.hpp>
#include <oscar/coordinator/applet.hpp>

#include <optional>
#include <sstream>
#include <stdexcept>

namespace {

class FrameModeSwitcher final : public oscar::coordinator::Applet {
 public:
  explicit FrameModeSwitcher(oscar::coordinator::AppletSetup& setup)
      : Applet(setup),
        bundle_(setup.param("bundle", "camera")),
        service_(setup.param("service", "Camera")),
        module_(setup.param("module", "cam")),
        kernel_(setup.param("kernel", module_)),
        insist_(setup.param("insist", "false") == "true"),
        every_(std::stoi(setup.param("switch_every_ms", "500"))) {
    std::istringstream modes(setup.param("modes", "quarter,half"));
    for (std::string m; std::getline(modes, m, ',');) modes_.push_back(m);
    if (modes_.empty()) throw std::invalid_argument("applet '" + name() + "': modes is empty");
    if (every_.count() <= 0) {
      throw std::invalid_argument("applet '" + name() + "': switch_every_ms must be > 0");
    }
  }

  void step(oscar::applets::AppletContext& ctx) override {
    // While it does not hold the camera it waits; one that insists commands anyway (and is
    // refused: the coordinator names the holder).
    const bool granted = ctx.granted(bundle_);
    if (granted != granted_) current_.reset();  // a new holder sets the mode afresh
    granted_ = granted;
    if (!granted && !insist_) return;
    const auto now = std::chrono::steady_clock::now();
    if (last_ && now - *last_ < every_) return;
    const auto& mode = modes_[next_ % modes_.size()];
    if (current_ == mode) return;  // one mode only: set once per grant
    last_ = now;
    oscar::SetFrameMode request;
    request.mode(mode);
    const auto reply = command(service_, module_, kernel_, "frame_mode", request);
    if (reply.ok()) {
      current_ = mode;
      ++next_;
      spdlog::info("applet {}: frame mode -> {}", name(), mode);
    } else {
      spdlog::warn("applet {}: frame mode {} refused: {}", name(), mode, reply.error());
    }
  }

  // A new holder sets its mode at once, not at its next step.
  bool on_interrupt(oscar::applets::AppletContext& ctx,
                    const oscar::applets::Notification& n) override {
    if (n.kind == oscar::applets::Notification::Kind::kGranted && bundle_name(n) == bundle_) {
      current_.reset();  // granted anew (perhaps given back and granted again since its last step)
      last_.reset();
      step(ctx);
    }
    return false;  // the rest as by default: a revocation is yielded at once
  }

  std::chrono::milliseconds period() const override { return std::chrono::milliseconds(20); }

 private:
  std::string bundle_, service_, module_, kernel_;
  bool insist_;
  std::chrono::milliseconds every_;
  std::vector<std::string> modes_;
  std::size_t next_ = 0;
  bool granted_ = false;
  std::optional<std::string> current_;  // the mode it set last while holding the camera
  std::optional<std::chrono::steady_clock::time_point> last_;
};

}  // namespace

OSCAR_REGISTER_APPLET(FrameModeSwitcher, "frame_mode_switcher")
