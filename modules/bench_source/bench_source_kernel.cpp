#include "bench_source_kernel.hpp"

#include <oscar/kernel_registry.hpp>

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

LineSeg3DSeq make_lines(int n) {
  LineSeg3DSeq cue;
  for (int i = 0; i < n; ++i) {
    LineSeg3D l;
    l.sx(i);
    l.sy(0.5 * i);
    l.sz(1.0);
    l.ex(i + 1.0);
    l.ey(0.5 * i);
    l.ez(1.0);
    cue.lines().push_back(l);
  }
  return cue;
}

GvImage make_image(int dx, int dy) {
  GvImage cue;
  cue.dx(static_cast<std::int16_t>(dx));
  cue.dy(static_cast<std::int16_t>(dy));
  cue.image().resize(static_cast<std::size_t>(dx) * static_cast<std::size_t>(dy));
  for (int y = 0; y < dy; ++y) {
    for (int x = 0; x < dx; ++x) {
      cue.image()[static_cast<std::size_t>(y) * dx + x] = static_cast<std::uint8_t>((x + y) & 0xff);
    }
  }
  return cue;
}
}  // namespace

BenchSource::BenchSource(KernelSetup& setup) {
  setup.params(params_);
  if (params_.type == "Bool") {
    Bool b;
    b.value(true);
    ports_ = std::make_unique<TypedPorts<Bool>>(setup, b);
  } else if (params_.type == "LineSeg3DSeq") {
    ports_ = std::make_unique<TypedPorts<LineSeg3DSeq>>(setup, make_lines(params_.lines));
  } else {
    ports_ = std::make_unique<TypedPorts<GvImage>>(setup, make_image(params_.dx, params_.dy));
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
