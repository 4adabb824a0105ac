// Publishes a Bool that toggles every `period` cycles, and its rhythm in a type of its own.
#include <oscar/cue_types.hpp>
#include <oscar/kernel.hpp>
#include <oscar/kernel_registry.hpp>

#include "blinker_rhythm.hpp"

class Blinker final : public oscar::Kernel {
 public:
  struct Params {
    int period = 2;
    void describe(oscar::ParamSpec& spec) {
      spec.field("period", period, "cycles per state").at_least(1);
    }
  };
  explicit Blinker(oscar::KernelSetup& setup)
      : out_(setup.output<oscar::Bool>("light")), rhythm_(setup.output<blinker::Rhythm>("rhythm")) {
    setup.params(params_);
  }
  void process(oscar::Cycle& cycle) override {
    oscar::Bool b;
    b.value((cycle.index() - 1) / static_cast<std::uint64_t>(params_.period) % 2 == 0);
    out_.publish(b);
    blinker::Rhythm r;
    r.period(params_.period);
    r.on(b.value());
    rhythm_.publish(r);
  }
  void stub(oscar::Cycle&) override {
    out_.publish(oscar::Bool{});
    rhythm_.publish(blinker::Rhythm{});
  }

 private:
  oscar::Output<oscar::Bool>& out_;
  oscar::Output<blinker::Rhythm>& rhythm_;
  Params params_;
};

OSCAR_REGISTER_KERNEL(Blinker, "blinker")
