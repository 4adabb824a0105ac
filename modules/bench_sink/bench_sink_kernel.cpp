#include "bench_sink_kernel.hpp"

#include <algorithm>
#include <fstream>
#include <map>

#include <iterator>

#include <fmt/format.h>
#include <oscar/kernel_registry.hpp>

#include "bench_plain.hpp"  // modules/bench_source

namespace oscar::modules {

void BenchSink::Params::describe(ParamSpec& spec) {
  spec.field("type", type, "cue type")
      .one_of(std::vector<std::string>(std::begin(bench_pattern::kBenchTypes),
                                       std::end(bench_pattern::kBenchTypes)))
      .fixed();
  spec.field("report", report, "JSON report file (empty: log only)");
  spec.field("expect", expect, "write the report after this many cues; 0 = at the end").at_least(0);
  spec.field("warmup", warmup, "cues left out of the latency figures").at_least(0);
  spec.field("log_every", log_every, "log a progress line this often; 0s = never");
  spec.field("verify", verify, "check each payload's checksum against bench_source's pattern");
}

struct BenchSink::Ports {
  virtual ~Ports() = default;
  virtual void consume(Cycle& cycle, Stats& stats, const Params& params) = 0;
};

namespace {
template <class T>
struct TypedPorts final : BenchSink::Ports {
  explicit TypedPorts(KernelSetup& setup) : in(setup.input<T>("in", {.depth = 16})) {}
  void consume(Cycle& cycle, BenchSink::Stats& s, const BenchSink::Params& params) override {
    const auto warmup = params.warmup;
    for (const auto& r : in.take_new()) {
      const auto& h = r.cue->header();
      if (s.received > 0 && h.seq() <= s.last_seq) {
        ++s.duplicates;
        continue;
      }
      if (s.received > 0 && h.seq() > s.last_seq + 1) s.gaps += h.seq() - s.last_seq - 1;
      if (s.received == 0) s.first_seq = h.seq();
      s.last_seq = h.seq();
      ++s.received;
      if (params.verify) {
        ++s.verified;
        s.corrupt += bench_pattern::checksum(*r.cue) != expected(*r.cue);
      }
      const auto n = bench_pattern::stamp_count(h);
      s.stamps_min = s.received == 1 ? n : std::min<std::uint64_t>(s.stamps_min, n);
      s.stamps_max = std::max<std::uint64_t>(s.stamps_max, n);
      if (static_cast<std::int64_t>(s.received) <= warmup || n == 0) continue;
      const auto generated = generation_stamp(h);
      if (s.delivery_ns.empty()) s.first_generated_ns = generated;
      s.last_generated_ns = generated;
      s.delivery_ns.push_back(r.received - generated);
      s.process_ns.push_back(cycle.now() - generated);
    }
  }
  // bench_source's checksum for the shape of `cue`, computed once per shape.
  std::uint64_t expected(const T& cue) {
    const auto [it, added] = expected_by_shape.try_emplace(bench_pattern::shape_of(cue), 0);
    if (added) it->second = bench_pattern::expected_checksum(cue);
    return it->second;
  }
  Input<T>& in;
  std::map<std::uint64_t, std::uint64_t> expected_by_shape;
};

struct Percentiles {
  double p50 = 0, p90 = 0, p99 = 0, max = 0;
};
Percentiles percentiles_us(std::vector<std::int64_t> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))] /
           1e3;
  };
  return {at(0.5), at(0.9), at(0.99), v.back() / 1e3};
}
}  // namespace

BenchSink::BenchSink(KernelSetup& setup) {
  setup.params(params_);
  ports_ = bench_pattern::visit_bench_type(params_.type, [&]<class T>() -> std::unique_ptr<Ports> {
    return std::make_unique<TypedPorts<T>>(setup);
  });
}

BenchSink::~BenchSink() = default;

void BenchSink::process(Cycle& cycle) {
  ports_->consume(cycle, stats_, params_);
  if (params_.log_every.count() > 0 && cycle.now() - last_log_ >= params_.log_every.count()) {
    if (last_log_ != 0) {
      const double seconds = static_cast<double>(cycle.now() - last_log_) / 1e9;
      const auto recent = std::vector<std::int64_t>(
          stats_.delivery_ns.end() -
              static_cast<std::ptrdiff_t>(std::min<std::size_t>(
                  stats_.delivery_ns.size(), stats_.received - received_at_last_log_)),
          stats_.delivery_ns.end());
      cycle.log().info(
          "{}: {} cues ({:.1f} Hz), last seq {}, gaps {}, latency p50 {:.0f} us, {} stamps",
          params_.type, stats_.received,
          static_cast<double>(stats_.received - received_at_last_log_) / seconds, stats_.last_seq,
          stats_.gaps, percentiles_us(recent).p50, stats_.stamps_max);
    }
    last_log_ = cycle.now();
    received_at_last_log_ = stats_.received;
  }
  if (params_.expect > 0 && !reported_ &&
      static_cast<std::int64_t>(stats_.received) >= params_.expect) {
    write_report();
    reported_ = true;
  }
}

// A sink has no outputs; in stub mode it still counts, so a source can be tested against it.
void BenchSink::stub(Cycle& cycle) { process(cycle); }

void BenchSink::on_deactivate() {
  if (!reported_) write_report();
}

std::string BenchSink::report() const {
  const auto d = percentiles_us(stats_.delivery_ns);
  const auto p = percentiles_us(stats_.process_ns);
  return fmt::format(
      R"({{"type":"{}","received":{},"gaps":{},"duplicates":{},"first_seq":{},"last_seq":{},)"
      R"("verified":{},"corrupt":{},"stamps_min":{},"stamps_max":{},"samples":{},"span_s":{:.6f},)"
      R"("delivery_us":{{"p50":{:.2f},"p90":{:.2f},"p99":{:.2f},"max":{:.2f}}},)"
      R"("process_us":{{"p50":{:.2f},"p90":{:.2f},"max":{:.2f}}}}})",
      params_.type, stats_.received, stats_.gaps, stats_.duplicates, stats_.first_seq,
      stats_.last_seq, stats_.verified, stats_.corrupt, stats_.stamps_min, stats_.stamps_max,
      stats_.delivery_ns.size(),
      static_cast<double>(stats_.last_generated_ns - stats_.first_generated_ns) / 1e9, d.p50, d.p90,
      d.p99, d.max, p.p50, p.p90, p.max);
}

void BenchSink::write_report() const {
  if (params_.report.empty()) return;
  const auto tmp = params_.report + ".tmp";
  {
    std::ofstream out(tmp);
    out << report() << "\n";
  }
  std::rename(tmp.c_str(), params_.report.c_str());  // readers never see half a report
}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::BenchSink, "bench_sink")
