// oscar bench cueflow --throughput (issue 21 item 5, docs/benchmarks.md "Throughput").
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "cueflow_runs.hpp"
#include "peers/peer_list.hpp"

namespace oscar::bench {

// Issue 21 item 5: per row, the highest rate at which a trial of `seconds` (after a second of
// warm-up) loses no cue, OSCAR beside its baseline, and the CPU % of that trial's processes
// (user + system over the trial's wall time, start-up included; 100 = one core). The baseline is
// raw Fast DDS (listener, synchronous, shared memory) for multicore and local, raw iceoryx for
// local_zero_copy (OSCAR with the row's plain type; both through a RouDi started here, whose own
// CPU is not counted). No remote rows.
int run_throughput(const std::vector<std::string>& types,
                   const std::vector<std::string>& constellations, double seconds, int domain,
                   const std::string& dir, bool json) {
  const auto trial = [&](const Row& r, const std::string& constellation, bool raw) {
    return [&, r, constellation, raw](double rate) -> std::optional<Trial> {
      const bool multicore = constellation == "multicore",
                 zero_copy = constellation == "local_zero_copy";
      Row at = r;
      at.period_us = std::max(1, static_cast<int>(std::lround(1e6 / rate)));
      const int n = static_cast<int>(rate * seconds), warm = static_cast<int>(rate);
      Bench b(n, warm, domain, dir);
      rusage before{}, after{};
      getrusage(RUSAGE_CHILDREN, &before);
      const auto start = std::chrono::steady_clock::now();
      const auto l =
          raw ? (zero_copy ? b.program("oscar-bench-iceoryx", {}, at, false)
                           : b.program("oscar-bench-raw", raw_config_args("listener,sync,shm"), at,
                                       multicore))
              : (zero_copy ? b.framework_zero_copy(at) : b.framework(at, multicore));
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      getrusage(RUSAGE_CHILDREN, &after);
      const auto cpu_s = [](const rusage& u) {
        return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
               static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
      };
      const bool lossless = l && l->gaps == 0 && l->samples >= n;
      std::cerr << fmt::format("bench cueflow: throughput {} {} {} at {:.0f} Hz: {}\n", r.type,
                               constellation, raw ? "raw" : "oscar", rate,
                               !l         ? "no report"
                               : lossless ? "no loss"
                                          : fmt::format("{} lost", l->gaps));
      if (!lossless) return std::nullopt;
      return Trial{(cpu_s(after) - cpu_s(before)) / wall * 100, l->rate_hz()};
    };
  };
  std::unique_ptr<test::Process> roudi;
  auto wanted = constellations;
  if (std::find(wanted.begin(), wanted.end(), "local_zero_copy") != wanted.end()) {
#if OSCAR_ZERO_COPY
    roudi = start_roudi(dir);
#else
    std::cerr << "bench cueflow: local_zero_copy rows skipped: this OSCAR was built without "
                 "iceoryx (libiceoryx-posh-dev)\n";
#endif
    if (!roudi) std::erase(wanted, "local_zero_copy");
  }
  nlohmann::json rows = nlohmann::json::array();
  if (!json) {
    std::cout << fmt::format(
        "highest rate asked for that lost no cue over {:g} s, the rate the cues came at, and the "
        "CPU of that trial\n{:<13} {:<15} {:>9} {:>9} {:>6} {:>9} {:>9} {:>6}\n",
        seconds, "type", "constell.", "oscar Hz", "came Hz", "CPU %", "raw Hz", "came Hz", "CPU %");
  }
  for (const auto& r : kRows) {
    if (std::find(types.begin(), types.end(), r.type) == types.end()) continue;
    for (const auto& c : wanted) {
      if (c == "remote") continue;
      const double start = 1e6 / r.period_us, cap = start * 128;
      const auto ours = highest_lossless_rate(start, cap, 3, trial(r, c, false));
      const auto raw = highest_lossless_rate(start, cap, 3, trial(r, c, true));
      const auto* baseline = c == "local_zero_copy" ? "iceoryx" : "fastdds";
      for (const auto& [system, t] : {std::pair{"oscar", ours}, std::pair{baseline, raw}}) {
        rows.push_back({{"system", system},
                        {"type", r.type},
                        {"bytes", r.bytes},
                        {"constellation", c},
                        {"max_lossless_hz", t.rate_hz},
                        {"achieved_hz", t.at.achieved_hz},
                        {"cpu_pct", t.at.cpu_pct},
                        {"seconds", seconds},
                        {"capped", t.rate_hz >= cap}});
      }
      if (!json) {
        std::cout << fmt::format(
                         "{:<13} {:<15} {:>9.0f} {:>9.0f} {:>6.1f} {:>9.0f} {:>9.0f} {:>6.1f}\n",
                         r.type, c, ours.rate_hz, ours.at.achieved_hz, ours.at.cpu_pct, raw.rate_hz,
                         raw.at.achieved_hz, raw.at.cpu_pct)
                  << std::flush;
      }
    }
  }
  if (json) std::cout << nlohmann::json{{"throughput", rows}}.dump() << "\n";
  return 0;
}

}  // namespace oscar::bench
