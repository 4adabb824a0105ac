#pragma once
// What every program of `oscar bench cueflow` shares (oscar-bench-raw and the peers of --all):
// the command line (pub/sub/both, --type, --count, --expect, --warmup, --period-us, --report,
// --domain), the payload size of each row, the clock and the report the bench reads:
//   {"type":T,"received":N,"gaps":N,"samples":N,"delivery_us":{"p50":..,"p90":..,"p99":..,"max":..}}
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

namespace oscar::bench {

struct PeerOptions {
  std::string mode;  // pub, sub or both (one process, publisher and subscriber threads)
  std::string type = "Bool";
  std::string report;
  int count = 1000, expect = 1000, warmup = 50, period_us = 2000, domain = 0;
};

inline void add_peer_options(CLI::App& app, PeerOptions& o) {
  app.add_option("mode", o.mode, "pub, sub or both")
      ->required()
      ->check(CLI::IsMember({"pub", "sub", "both"}));
  app.add_option("--type", o.type, "the row: Bool, LineSeg3DSeq or GvImage")
      ->check(CLI::IsMember({"Bool", "LineSeg3DSeq", "GvImage"}));
  app.add_option("--count", o.count, "cues the publisher sends at most");
  app.add_option("--expect", o.expect, "cues the subscriber waits for (warm-up included)");
  app.add_option("--warmup", o.warmup, "cues left out at the start");
  app.add_option("--period-us", o.period_us, "publishing period");
  app.add_option("--report", o.report, "JSON report the subscriber writes");
  app.add_option("--domain", o.domain, "DDS domain (or what keeps runs apart)");
}

/// The serialized size of the row's OSCAR cue payload, which the peers send as raw bytes:
/// Bool 1 B, LineSeg3DSeq of 100 lines 4800 B, a 768x576 GvImage 442368 B.
inline std::size_t payload_bytes(const std::string& type) {
  if (type == "LineSeg3DSeq") return 4800;
  if (type == "GvImage") return 768u * 576u;
  return 1;
}

/// CLOCK_MONOTONIC in nanoseconds: the peers' stamp and arrival clock (one host).
inline std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// The value at quantile q of sorted values (the bench's definition: index q * n, clamped).
inline double quantile(const std::vector<std::int64_t>& sorted, double q) {
  if (sorted.empty()) return 0;
  return static_cast<double>(
      sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(q * sorted.size()))]);
}

/// The subscriber's record: arrival minus stamp of each cue after the warm-up, until `expect`
/// cues have arrived. Thread-safe; done() may be polled from another thread.
class LatencyLog {
 public:
  explicit LatencyLog(const PeerOptions& o) : o_(o) { latency_ns_.reserve(o.expect); }

  /// With the cue's sequence number (`seq` > 0) the log also counts the cues missing between
  /// two that arrived (`gaps` in the report; the throughput search's loss).
  void add(std::int64_t latency_ns, std::uint64_t seq = 0) {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard lock(mutex_);
    if (done_) return;  // what arrives after the last expected cue is not counted
    if (seq > 0 && last_seq_ > 0 && seq > last_seq_ + 1) gaps_ += seq - last_seq_ - 1;
    if (seq > last_seq_) last_seq_ = seq;
    ++received_;
    if (received_ > o_.warmup) {
      if (latency_ns_.empty()) first_ = now;
      last_ = now;
      latency_ns_.push_back(latency_ns);
    }
    if (received_ >= o_.expect) done_ = true;
  }
  bool done() const { return done_; }

  void write_report() {
    std::lock_guard lock(mutex_);
    auto v = latency_ns_;
    std::sort(v.begin(), v.end());
    const auto us = [&](double q) { return quantile(v, q) / 1e3; };
    std::ofstream(o_.report) << fmt::format(
        R"({{"type":"{}","received":{},"gaps":{},"samples":{},"span_s":{:.6f},"delivery_us":{{"p50":{:.2f},"p90":{:.2f},"p99":{:.2f},"max":{:.2f}}}}})"
        "\n",
        o_.type, received_, gaps_, v.size(), std::chrono::duration<double>(last_ - first_).count(),
        us(0.5), us(0.9), us(0.99), v.empty() ? 0.0 : v.back() / 1e3);
  }

 private:
  const PeerOptions& o_;
  std::mutex mutex_;
  int received_ = 0;
  std::uint64_t last_seq_ = 0, gaps_ = 0;
  std::chrono::steady_clock::time_point first_{}, last_{};  // arrivals of the measured cues
  std::vector<std::int64_t> latency_ns_;
  std::atomic<bool> done_ = false;
};

/// Set once SIGTERM or SIGINT arrived (install_stop_handler): the bench stops a publisher that
/// way once its subscriber has reported, and the program leaves through its destructors (no
/// shared-memory files left behind).
inline volatile std::sig_atomic_t& stop_requested() {
  static volatile std::sig_atomic_t flag = 0;
  return flag;
}
inline void install_stop_handler() {
  const auto handler = +[](int) { stop_requested() = 1; };
  std::signal(SIGTERM, handler);
  std::signal(SIGINT, handler);
}

/// Sleeps the publisher to its next period (absolute, so a late cue does not shift the rest).
class Pacer {
 public:
  explicit Pacer(int period_us) : period_(period_us), next_(std::chrono::steady_clock::now()) {}
  void wait() {
    next_ += period_;
    std::this_thread::sleep_until(next_);
  }

 private:
  std::chrono::microseconds period_;
  std::chrono::steady_clock::time_point next_;
};

}  // namespace oscar::bench
