#include "bench_source_kernel.hpp"

#include <iterator>
#include <type_traits>

#include <oscar/kernel_registry.hpp>

#include "bench_plain.hpp"

namespace oscar::modules {

void BenchSource::Params::describe(ParamSpec& spec) {
  spec.field("type", type, "cue type (the Plain ones go zero-copy on one host)")
      .one_of(std::vector<std::string>(std::begin(bench_pattern::kBenchTypes),
                                       std::end(bench_pattern::kBenchTypes)))
      .fixed();
  spec.field("lines", lines, "lines per LineSeg3DSeq (100 = 4800 bytes; Plain: at most 256)")
      .range(0, 1'000'000);
  spec.field("dx", dx, "GvImage columns (Plain: dx x dy at most 768 x 576)").range(1, 32767);
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
  // Filled before the frame stamps it, where it is published from: on the zero-copy path, in
  // the shared-memory chunk the sink reads.
  void publish() override {
    auto cue = out.loan();
    *cue = prototype;
    out.publish(std::move(cue));
  }
  Output<T>& out;
  T prototype;
};

template <class T>
T payload(const BenchSource::Params& p) {
  namespace bp = bench_pattern;
  if constexpr (std::is_same_v<T, Bool> || std::is_same_v<T, PlainBool>) {
    T b;
    b.value(true);
    return b;
  } else if constexpr (std::is_same_v<T, LineSeg3DSeq>) {
    return bp::lines(p.lines);
  } else if constexpr (std::is_same_v<T, PlainLineSeg3DSeq>) {
    return bp::plain_lines(p.lines);
  } else if constexpr (std::is_same_v<T, GvImage>) {
    return bp::image(p.dx, p.dy);
  } else {
    return bp::plain_image(p.dx, p.dy);
  }
}
}  // namespace

BenchSource::BenchSource(KernelSetup& setup) {
  setup.params(params_);
  ports_ = bench_pattern::visit_bench_type(params_.type, [&]<class T>() -> std::unique_ptr<Ports> {
    return std::make_unique<TypedPorts<T>>(setup, payload<T>(params_));
  });
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
