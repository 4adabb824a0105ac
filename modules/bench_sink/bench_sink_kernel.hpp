#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <oscar/cue_types.hpp>
#include <oscar/kernel.hpp>

namespace oscar::modules {

/// Consumes benchmark cues: counts them, counts sequence gaps and duplicates, with `verify`
/// counts cues whose payload is not bench_source's (by checksum), and measures the one-way latency
/// from the header's first stamp to the cue's arrival at the input (delivery) and to the start of
/// the cycle that processes it. Writes a JSON report when `expect` cues have arrived and when
/// deactivated.
class BenchSink final : public Kernel {
 public:
  struct Params {
    std::string type = "Bool";
    std::string report;       ///< JSON report file; empty = only log
    std::int64_t expect = 0;  ///< write the report once this many cues arrived; 0 = at the end
    std::int64_t warmup = 0;  ///< cues to leave out of the latency figures
    std::chrono::nanoseconds log_every{0};  ///< log a progress line this often; 0 = never
    bool verify = false;  ///< check each payload's checksum against bench_source's pattern
    void describe(ParamSpec& spec);
  };
  struct Stats {
    std::uint64_t received = 0, gaps = 0, duplicates = 0, first_seq = 0, last_seq = 0;
    std::uint64_t verified = 0, corrupt = 0;  ///< payloads checked; of those, not as sent
    std::vector<std::int64_t> delivery_ns, process_ns;
    std::uint64_t stamps_min = 0, stamps_max = 0;  ///< header stamp count (fusion depth)
    /// When the first and the last measured cue were made: what the source achieved.
    std::int64_t first_generated_ns = 0, last_generated_ns = 0;
  };
  explicit BenchSink(KernelSetup& setup);
  ~BenchSink() override;
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  void on_deactivate() override;
  const Stats& stats() const { return stats_; }
  /// The report as JSON text.
  std::string report() const;
  struct Ports;

 private:
  void write_report() const;
  Params params_;
  std::unique_ptr<Ports> ports_;
  Stats stats_;
  bool reported_ = false;
  Stamp last_log_ = 0;
  std::uint64_t received_at_last_log_ = 0;
};

}  // namespace oscar::modules
