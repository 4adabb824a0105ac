#pragma once
// The arithmetic of `oscar bench cueflow`, apart from running processes (so it is testable):
// reading a program's report, medians over runs, the fastest raw Fast DDS configuration, the
// search for the highest rate without loss.
#include <algorithm>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oscar::bench {

struct Latency {
  double p50 = 0, p90 = 0, p99 = 0, max = 0;
  long samples = 0;
  long gaps = 0;      ///< cues missing between two that arrived (0 where the report does not say)
  double span_s = 0;  ///< from the first to the last measured cue (0 where not said)
  /// bench_sink's only: from the stamp to the kernel's process() that reads the cue, the
  /// delivery plus the hand-over to the module's processing thread (0 where not said).
  double process_p50 = 0, process_p90 = 0;
  /// The rate the measured cues came at (0 without a span).
  double rate_hz() const { return span_s > 0 ? static_cast<double>(samples - 1) / span_s : 0; }
};

/// A report of oscar-bench-raw, a peer or bench_sink: {"samples":N,"delivery_us":{"p50",..}}.
/// p99, gaps and span are 0 where the report has none.
inline Latency parse_report(const nlohmann::json& j) {
  const auto& d = j.at("delivery_us");
  Latency l{d.at("p50"), d.at("p90"), d.value("p99", 0.0), d.at("max"), j.at("samples")};
  l.gaps = j.value("gaps", 0L);
  l.span_s = j.value("span_s", 0.0);
  if (const auto p = j.find("process_us"); p != j.end()) {
    l.process_p50 = p->at("p50");
    l.process_p90 = p->at("p90");
  }
  return l;
}

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

/// The median of each figure over repeated runs; samples are summed.
inline Latency median_of(const std::vector<Latency>& runs) {
  std::vector<double> p50, p90, p99, max, process_p50, process_p90;
  long samples = 0;
  for (const auto& r : runs) {
    p50.push_back(r.p50);
    p90.push_back(r.p90);
    p99.push_back(r.p99);
    max.push_back(r.max);
    process_p50.push_back(r.process_p50);
    process_p90.push_back(r.process_p90);
    samples += r.samples;
  }
  Latency m{median(p50), median(p90), median(p99), median(max), samples};
  m.process_p50 = median(process_p50);
  m.process_p90 = median(process_p90);
  return m;
}

/// The raw Fast DDS configurations the bench tries: delivery, publish mode, transport.
inline std::vector<std::string> raw_configs() {
  std::vector<std::string> out;
  for (const char* delivery : {"waitset", "listener"}) {
    for (const char* publish : {"sync", "async"}) {
      for (const char* transport : {"shm", "udp"}) {
        out.push_back(std::string(delivery) + "," + publish + "," + transport);
      }
    }
  }
  return out;
}

/// Whether `a` is faster than `b`: the lower p50, then the lower p90.
inline bool faster(const Latency& a, const Latency& b) {
  return a.p50 < b.p50 || (a.p50 == b.p50 && a.p90 < b.p90);
}

/// The fastest configuration that delivered (the first name among equals); none if none did.
inline std::optional<std::string> fastest(const std::map<std::string, Latency>& by_config) {
  std::optional<std::string> best;
  for (const auto& [config, l] : by_config) {
    if (l.samples > 0 && (!best || faster(l, by_config.at(*best)))) best = config;
  }
  return best;
}

/// "waitset,sync,shm" as oscar-bench-raw's options.
inline std::vector<std::string> raw_config_args(const std::string& config) {
  std::vector<std::string> parts;
  std::size_t from = 0;
  for (std::size_t comma; (comma = config.find(',', from)) != std::string::npos; from = comma + 1) {
    parts.push_back(config.substr(from, comma - from));
  }
  parts.push_back(config.substr(from));
  if (parts.size() != 3) throw std::invalid_argument("raw config '" + config + "': want D,P,T");
  return {"--delivery", parts[0], "--publish", parts[1], "--transport", parts[2]};
}

/// A trial of the throughput search that lost no cue: the CPU % of its processes and the rate
/// its measured cues came at.
struct Trial {
  double cpu_pct = 0, achieved_hz = 0;
};

/// What the throughput search found: the highest rate (Hz) asked for that a trial passed (0: not
/// even the first), that trial, and the rates tried in order.
struct Throughput {
  double rate_hz = 0;
  Trial at;
  std::vector<double> tried;
};

/// The highest rate without loss: `trial(rate)` runs at that rate and returns what it measured
/// if no cue was lost, nothing otherwise. From `start_hz` the rate doubles until a trial fails or
/// `max_hz` passes; then `bisections` halve the interval between the last rate that passed and
/// the first that failed.
inline Throughput highest_lossless_rate(double start_hz, double max_hz, int bisections,
                                        const std::function<std::optional<Trial>(double)>& trial) {
  Throughput t;
  double failed = 0;
  for (double rate = start_hz; rate <= max_hz; rate *= 2) {
    t.tried.push_back(rate);
    const auto passed = trial(rate);
    if (!passed) {
      failed = rate;
      break;
    }
    t.rate_hz = rate;
    t.at = *passed;
  }
  if (failed == 0) return t;  // every rate up to max_hz passed
  double good = t.rate_hz, bad = failed;
  for (int i = 0; i < bisections && good > 0; ++i) {
    const double rate = (good + bad) / 2;
    t.tried.push_back(rate);
    if (const auto passed = trial(rate)) {
      good = rate;
      t.rate_hz = rate;
      t.at = *passed;
    } else {
      bad = rate;
    }
  }
  return t;
}

}  // namespace oscar::bench
