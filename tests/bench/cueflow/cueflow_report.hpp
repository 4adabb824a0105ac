#pragma once
// The arithmetic of `oscar bench cueflow`, apart from running processes (so it is testable):
// reading a program's report, medians over runs, the fastest raw Fast DDS configuration.
#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oscar::bench {

struct Latency {
  double p50 = 0, p90 = 0, p99 = 0, max = 0;
  long samples = 0;
};

/// A report of oscar-bench-raw, a peer or bench_sink: {"samples":N,"delivery_us":{"p50",..}}.
/// p99 is 0 where the report has none.
inline Latency parse_report(const nlohmann::json& j) {
  const auto& d = j.at("delivery_us");
  return {d.at("p50"), d.at("p90"), d.value("p99", 0.0), d.at("max"), j.at("samples")};
}

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

/// The median of each figure over repeated runs; samples are summed.
inline Latency median_of(const std::vector<Latency>& runs) {
  std::vector<double> p50, p90, p99, max;
  long samples = 0;
  for (const auto& r : runs) {
    p50.push_back(r.p50);
    p90.push_back(r.p90);
    p99.push_back(r.p99);
    max.push_back(r.max);
    samples += r.samples;
  }
  return {median(p50), median(p90), median(p99), median(max), samples};
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

}  // namespace oscar::bench
