#include "bench_source_kernel.hpp"

#include <oscar/kernel_registry.hpp>

#include "bench_pattern.hpp"

namespace oscar::modules {

void BenchSource::Params::describe(ParamSpec& spec) {
  spec.field("type", type, "cue type").one_of({"Bool", "LineSeg3DSeq", "GvImage"}).fixed();
  spec.field("lines", lines, "lines per LineSeg3DSeq (100 = 4800 bytes)").range(0, 1'000'000);
  spec.field("dx", dx, "GvImage columns").range(1, 32767);
  spec.field("dy", dy, "GvImage rows").range(1, 32767);
  spec.field("count", count, "cues to publish before going quiet; 0 = unlimited").at_least(0);
}

struct BenchSource::Ports {
  virtual ~Ports() = default;
  virtual void publish() = 0;
};

namespace {
template <class T>
struct TypedPorts final : BenchSource::Ports {
  TypedPorts(KernelSetup& setup, const T& cue) : out(setup.output<T>("out")), prototype(cue) {}
  void publish() override { out.publish(prototype); }  // the frame stamps and numbers it
  Output<T>& out;
  T prototype;
};
}  // namespace

BenchSource::BenchSource(KernelSetup& setup) {
  setup.params(params_);
  if (params_.type == "Bool") {
    Bool b;
    b.value(true);
    ports_ = std::make_unique<TypedPorts<Bool>>(setup, b);
  } else if (params_.type == "LineSeg3DSeq") {
    ports_ = std::make_unique<TypedPorts<LineSeg3DSeq>>(setup, bench_pattern::lines(params_.lines));
  } else {
    ports_ =
        std::make_unique<TypedPorts<GvImage>>(setup, bench_pattern::image(params_.dx, params_.dy));
  }
}

BenchSource::~BenchSource() = default;

void BenchSource::process(Cycle&) {
  if (params_.count > 0 && sent_ >= params_.count) return;
  ++sent_;
  ports_->publish();
}

// The benchmark cues are synthetic already; stub mode publishes the same.
void BenchSource::stub(Cycle& cycle) { process(cycle); }

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::BenchSource, "bench_source")
