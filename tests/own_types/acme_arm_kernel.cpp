// A kernel of types OSCAR does not define (acme_arm.idl), for the tests of what OSCAR's tools
// make of them: it publishes the arm's state each cycle and holds a grip when commanded.
#include <cmath>

#include <fmt/format.h>

#include <acme_arm/acme_arm.h>
#include <acme_arm/acme_armPubSubTypes.h>
#include <oscar/cue.hpp>
#include <oscar/kernel.hpp>
#include <oscar/kernel_registry.hpp>

OSCAR_DECLARE_CUE_TYPE(acme, ArmState)
OSCAR_DECLARE_IDL_TYPE(acme, HoldRequest)

namespace {

class AcmeArm final : public oscar::Kernel {
 public:
  struct Params {
    std::string tool = "gripper";
    void describe(oscar::ParamSpec& spec) { spec.field("tool", tool, "the tool's name"); }
  };
  explicit AcmeArm(oscar::KernelSetup& setup) : state_(setup.output<acme::ArmState>("state")) {
    setup.params(params_);
    setup.command<acme::HoldRequest>("hold", [this](const acme::HoldRequest& r) {
      if (r.seconds() <= 0) return oscar::CommandAnswer::refuse("seconds must be above 0");
      grip_ = r.grip();
      return oscar::CommandAnswer::accept(fmt::format(
          "holding {} for {} s", grip_ == acme::GRIP_CLOSED ? "closed" : "open", r.seconds()));
    });
  }
  void process(oscar::Cycle& cycle) override {
    acme::ArmState s;
    const auto t = static_cast<double>(cycle.index());
    s.joints_rad({0.1 * t, std::sin(0.1 * t), -0.5});
    s.grip(grip_);
    s.tool(params_.tool);
    state_.publish(s);
  }
  void stub(oscar::Cycle&) override { state_.publish(acme::ArmState{}); }

 private:
  oscar::Output<acme::ArmState>& state_;
  Params params_;
  acme::Grip grip_ = acme::GRIP_OPEN;
};

}  // namespace

OSCAR_REGISTER_KERNEL(AcmeArm, "acme_arm")
