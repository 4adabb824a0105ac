#include "relay_kernel.hpp"

#include <oscar/kernel_registry.hpp>

namespace oscar::modules {

void Relay::Params::describe(ParamSpec& spec) {
  spec.field("type", type, "cue type to relay").one_of({"Bool", "LineSeg3DSeq", "GvImage"}).fixed();
}

struct Relay::Ports {
  virtual ~Ports() = default;
  virtual void forward(Cycle& cycle) = 0;
  virtual void stub(Cycle& cycle) = 0;
};

namespace {
template <class T>
struct TypedPorts final : Relay::Ports {
  explicit TypedPorts(KernelSetup& setup) : in(setup.input<T>("in")), out(setup.output<T>("out")) {}
  void forward(Cycle& cycle) override {
    for (const auto& r : in.take_new()) {
      T copy = *r.cue;
      append_stamp(copy.header(), cycle.now());
      out.publish(std::move(copy));
    }
  }
  void stub(Cycle& cycle) override {
    T cue;
    append_stamp(cue.header(), cycle.now());
    append_stamp(cue.header(), cycle.now());
    out.publish(std::move(cue));
  }
  Input<T>& in;
  Output<T>& out;
};
}  // namespace

Relay::Relay(KernelSetup& setup) {
  setup.params(params_);
  ports_ = visit_standard_type(params_.type, [&]<class T>() -> std::unique_ptr<Ports> {
    return std::make_unique<TypedPorts<T>>(setup);
  });
}

Relay::~Relay() = default;

void Relay::process(Cycle& cycle) { ports_->forward(cycle); }
void Relay::stub(Cycle& cycle) { ports_->stub(cycle); }

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::Relay, "relay")
