// oscar bench cueflow: seed 004 Abb. 8 (cue transfer time of Bool, LineSeg3DSeq with 100 lines
// and a 768x576 GvImage) for the multi-core, local and remote constellations, against raw Fast
// DDS with the same type and QoS, measured in the same run: multi-core and local in its fastest
// configuration (a pre-pass tries delivery, publish mode and transport per row), remote over UDP
// between two test hosts. --all adds the peers (Fast DDS data sharing, Cyclone DDS, iceoryx, a
// memcpy + futex floor) to the multi-core and local rows and Cyclone DDS to the remote ones, each
// its own program in peers/. Prints
// a table, or JSON (--json). docs/benchmarks.md explains the rows.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <span>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>

#include "cueflow_report.hpp"
#include "cueflow_runs.hpp"
#include "peers/peer_list.hpp"

namespace {
using namespace std::chrono_literals;
using oscar::test::Process;

using oscar::bench::await_report;
using oscar::bench::Bench;
using oscar::bench::bin;
using oscar::bench::kPeers;
using oscar::bench::kRows;
using oscar::bench::Latency;
using oscar::bench::median_of;
using oscar::bench::Peer;
using oscar::bench::Row;
using oscar::bench::start_roudi;

// The cue protections a keystore's governance may give cue topics (docs/security.md).
const char* const kProtections[] = {"none", "sign", "encrypt"};

// A keystore per cue protection for the two modules of the local constellation (src and sink),
// made by `oscar security init` in `dir`; by protection.
std::map<std::string, std::string> make_keystores(const std::filesystem::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto* protection : kProtections) {
    const auto file = dir / fmt::format("secured_{}.yaml", protection);
    std::ofstream(file) << fmt::format(R"(system: bench_cueflow
security: {{ cue_protection: {} }}
modules:
  - {{ name: src, kernels: [ {{ type: bench_source, name: src, params: {{ type: Bool }} }} ] }}
  - {{ name: sink, kernels: [ {{ type: bench_sink, name: sink, params: {{ type: Bool }}, inputs: {{ in: src/out }} }} ] }}
)",
                                       protection);
    const auto keystore = (dir / fmt::format("keys_{}", protection)).string();
    Process init({bin("oscar-security"), "init", file.string(), "--keystore", keystore},
                 (dir / fmt::format("keys_{}.log", protection)).string());
    if (init.wait(60s) != 0) {
      throw std::runtime_error("oscar security init failed: " + init.output());
    }
    out[protection] = keystore;
  }
  return out;
}

// `type`: the row's type as the bench names it (PlainBool in the zero-copy constellation).
nlohmann::json system_row(const std::string& system, const std::string& type, const Row& r,
                          const std::string& c, const Latency& l, std::size_t runs) {
  return {{"system", system},     {"type", type},    {"bytes", r.bytes}, {"constellation", c},
          {"p50_us", l.p50},      {"p90_us", l.p90}, {"p99_us", l.p99},  {"max_us", l.max},
          {"samples", l.samples}, {"runs", runs}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench cueflow: one-way cue latency, OSCAR vs raw Fast DDS (seed 004 Abb. 8)"};
  bool json = false, all = false;
  int count = 1000, warmup = 50, domain = 90, repeat = 3, prepass = 200;
  std::string raw_config = "auto";
  std::vector<std::string> types{"Bool", "LineSeg3DSeq", "GvImage"};
  std::vector<std::string> constellations{"multicore", "local", "remote"};
  if (OSCAR_ZERO_COPY) constellations.push_back("local_zero_copy");
  app.add_flag("--json", json, "print JSON instead of a table");
  app.add_option("--count", count, "measured cues per row (after the warm-up)")
      ->check(CLI::PositiveNumber);
  app.add_option("--warmup", warmup, "cues left out at the start of each row");
  app.add_option("--domain", domain, "DDS domain for the run");
  app.add_option("--repeat", repeat, "runs per row, OSCAR and raw alternating; medians reported")
      ->check(CLI::PositiveNumber);
  app.add_option("--types", types, "rows to run")->delimiter(',');
  app.add_option("--constellations", constellations,
                 "multicore, local, remote (two test hosts in network namespaces; root), "
                 "local_zero_copy (the plain types through a RouDi started here)")
      ->delimiter(',')
      ->check(CLI::IsMember({"multicore", "local", "remote", "local_zero_copy"}));
  oscar::bench::UdpSettings udp;
  app.add_option("--udp-buffer-bytes", udp.buffer_bytes,
                 "remote: UDP socket buffers of both sides (default OSCAR's 4 MiB; 0: the "
                 "system's)");
  app.add_option("--udp-max-message-bytes", udp.max_message_bytes,
                 "remote: largest UDP datagram (default and 0: Fast DDS's 65500)");
  app.add_option("--raw-config", raw_config,
                 "raw Fast DDS configuration 'delivery,publish,transport' (waitset|listener, "
                 "sync|async, shm|udp), or auto: the fastest of all in a pre-pass per row "
                 "(multicore and local)");
  app.add_option("--prepass-count", prepass,
                 "measured cues per configuration and round of the pre-pass")
      ->check(CLI::PositiveNumber);
  app.add_flag("--all", all,
               "add the peers: Fast DDS data sharing, Cyclone DDS, iceoryx, memcpy + futex floor");
  double throughput_s = 0;
  app.add_option("--throughput", throughput_s,
                 "instead of latency: the highest rate without loss over this many seconds per "
                 "trial (multicore, local, local_zero_copy), OSCAR beside raw Fast DDS (raw "
                 "iceoryx for local_zero_copy), and its CPU")
      ->check(CLI::PositiveNumber);
  bool security = false;
  app.add_flag("--security", security,
               "local rows also with DDS Security (keystores made here), cue topics unprotected, "
               "signed and encrypted, alternated with the plain runs");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  const auto dir = std::filesystem::temp_directory_path() / fmt::format("oscar_bench_{}", getpid());
  std::filesystem::create_directories(dir);
  if (throughput_s > 0) {
    const int code = oscar::bench::run_throughput(types, constellations, throughput_s, domain,
                                                  dir.string(), json);
    std::filesystem::remove_all(dir);
    return code;
  }
  Bench bench(count, warmup, domain, dir.string());
  const auto keystores = security ? make_keystores(dir) : std::map<std::string, std::string>{};
  std::unique_ptr<oscar::bench::RemoteHosts> hosts;
  if (std::find(constellations.begin(), constellations.end(), "remote") != constellations.end()) {
    if (const auto why = oscar::bench::RemoteHosts::unavailable(); !why.empty()) {
      std::cerr << "bench cueflow: remote rows skipped: " << why << "\n";
      std::erase(constellations, "remote");
    } else {
      hosts = std::make_unique<oscar::bench::RemoteHosts>(udp);
    }
  }
  std::vector<Peer> peers;
  std::unique_ptr<Process> roudi;  // for iceoryx and the zero-copy rows
  const auto have_roudi = [&] {
#if OSCAR_ZERO_COPY
    if (!roudi) roudi = start_roudi(dir);
#endif
    return roudi != nullptr;
  };
  for (const auto& peer : all ? std::span(kPeers) : std::span<const Peer>()) {
    if (!std::filesystem::exists(bin(peer.program))) {
      std::cerr << fmt::format("bench cueflow: {} not built (its package missing), no {} rows\n",
                               peer.program, peer.system);
    } else if (peer.system != std::string("iceoryx") || have_roudi()) {
      peers.push_back(peer);
    }
  }
  if (std::find(constellations.begin(), constellations.end(), "local_zero_copy") !=
      constellations.end()) {
    if (!OSCAR_ZERO_COPY) {
      std::cerr << "bench cueflow: local_zero_copy rows skipped: this OSCAR was built without "
                   "iceoryx (libiceoryx-posh-dev)\n";
      std::erase(constellations, "local_zero_copy");
    } else if (!have_roudi()) {
      std::erase(constellations, "local_zero_copy");
    }
  }
  nlohmann::json rows = nlohmann::json::array();
  std::vector<std::string> peer_lines;
  int failures = 0;
  if (!json) {
    std::cout << fmt::format(
        "{:<17} {:>7} {:<15} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10} {:>7} {:>10}  {}\n", "type",
        "bytes", "constell.", "p50 us", "p90 us", "p99 us", "max us", "proc p50", "raw p50",
        "ratio", "seed us", "raw config");
  }
  for (const auto& r : kRows) {
    if (std::find(types.begin(), types.end(), r.type) == types.end()) continue;
    for (const auto& c : constellations) {
      const bool multicore = c == "multicore", remote = c == "remote",
                 zero_copy = c == "local_zero_copy";
      // Remote: the raw program over the test hosts' UDP, in Fast DDS's default configuration.
      // Zero-copy: raw iceoryx is the baseline (the same RouDi, its own minimal program).
      std::string config = remote ? "listener,sync,udp" : zero_copy ? "iceoryx" : raw_config;
      const auto type = zero_copy ? "Plain" + r.type : r.type;
      if (config == "auto") {
        // Two rounds over all configurations, each keeping its better run: a hiccup of the
        // machine during one short run does not decide the baseline.
        std::map<std::string, Latency> tried;
        for (int round = 0; round < 2; ++round) {
          for (const auto& candidate : oscar::bench::raw_configs()) {
            const auto l = bench.program(
                "oscar-bench-raw", oscar::bench::raw_config_args(candidate), r, multicore, prepass);
            if (!l) continue;
            const auto kept = tried.find(candidate);
            if (kept == tried.end() || oscar::bench::faster(*l, kept->second)) {
              tried[candidate] = *l;
            }
          }
        }
        std::string tally;
        for (const auto& [candidate, l] : tried)
          tally += fmt::format(" {} {:.1f};", candidate, l.p50);
        const auto best = oscar::bench::fastest(tried);
        std::cerr << fmt::format("bench cueflow: {} {} pre-pass (p50 us):{} fastest {}\n", r.type,
                                 c, tally, best.value_or("none"));
        if (!best) {
          ++failures;
          continue;
        }
        config = *best;
      }
      const auto raw_args =
          zero_copy ? std::vector<std::string>{} : oscar::bench::raw_config_args(config);
      std::vector<Latency> ours_runs, raw_runs;
      std::map<std::string, std::vector<Latency>> secured_runs;  // by cue protection
      std::map<std::string, std::vector<Latency>> peer_runs;     // by system
      for (int i = 1; i <= repeat; ++i) {
        std::cerr << fmt::format("bench cueflow: {} {} run {}/{} ({} cues)...\n", r.type, c, i,
                                 repeat, count);
        const auto o = remote      ? bench.framework_remote(r, *hosts)
                       : zero_copy ? bench.framework_zero_copy(r)
                                   : bench.framework(r, multicore);
        const auto w = remote      ? bench.raw_remote(r, *hosts)
                       : zero_copy ? bench.program("oscar-bench-iceoryx", {}, r, false)
                                   : bench.program("oscar-bench-raw", raw_args, r, multicore);
        if (!o || !w) {
          std::cerr << fmt::format("bench cueflow: {} {}: no report from {} (logs in {})\n", r.type,
                                   c, o ? "raw Fast DDS" : "OSCAR", dir.string());
          ++failures;
          continue;
        }
        ours_runs.push_back(*o);
        raw_runs.push_back(*w);
        for (const auto& [protection, keystore] :
             multicore || remote || zero_copy ? decltype(keystores){} : keystores) {
          if (const auto s = bench.framework(r, false, keystore)) {
            secured_runs[protection].push_back(*s);
          } else {
            std::cerr << fmt::format("bench cueflow: {} {} secured ({}): no report (logs in {})\n",
                                     r.type, c, protection, dir.string());
            ++failures;
          }
        }
        for (const auto& peer : peers) {
          if (remote && !peer.remote) continue;  // a same-host mechanism
          // Zero-copy: raw iceoryx is the baseline above; the floor reads its slot in place, the
          // other peers are in the local rows.
          const bool floor = peer.system == std::string("floor");
          if (zero_copy && !floor) continue;
          const auto args =
              zero_copy ? std::vector<std::string>{"--in-place"} : std::vector<std::string>{};
          if (const auto l = remote ? bench.peer_remote(peer.program, r, *hosts)
                                    : bench.program(peer.program, args, r, multicore)) {
            peer_runs[peer.system].push_back(*l);
          } else {
            std::cerr << fmt::format("bench cueflow: {} {} {}: no report (logs in {})\n",
                                     peer.system, r.type, c, dir.string());
            ++failures;
          }
        }
      }
      if (ours_runs.empty()) continue;
      const auto ours = median_of(ours_runs);
      const auto raw = median_of(raw_runs);
      const double seed =
          multicore ? r.seed_multicore_us : (remote ? r.seed_remote_us : r.seed_local_us);
      // The ratio of medians: each run's p50 is a median already, runs alternate OSCAR and raw.
      const double ratio = raw.p50 > 0 ? ours.p50 / raw.p50 : 0;
      rows.push_back({{"system", "oscar"},
                      {"type", type},
                      {"bytes", r.bytes},
                      {"constellation", c},
                      {"p50_us", ours.p50},
                      {"p90_us", ours.p90},
                      {"p99_us", ours.p99},
                      {"max_us", ours.max},
                      {"raw_p50_us", raw.p50},
                      {"raw_p90_us", raw.p90},
                      {"raw_p99_us", raw.p99},
                      {"raw_max_us", raw.max},
                      {"process_p50_us", ours.process_p50},
                      {"process_p90_us", ours.process_p90},
                      {"raw_config", config},
                      {"ratio", ratio},
                      {"samples", ours.samples},
                      {"runs", ours_runs.size()},
                      {"seed_us", seed}});
      if (!json) {
        std::cout << fmt::format(
                         "{:<17} {:>7} {:<15} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} "
                         "{:>10.1f} {:>7.2f} {:>10.0f}  {}\n",
                         type, r.bytes, c, ours.p50, ours.p90, ours.p99, ours.max, ours.process_p50,
                         raw.p50, ratio, seed, config)
                  << std::flush;
      }
      for (const auto* protection : kProtections) {  // in order of cost
        if (!secured_runs.contains(protection)) continue;
        const auto& runs = secured_runs[protection];
        const auto s = median_of(runs);
        const double vs_plain = ours.p50 > 0 ? s.p50 / ours.p50 : 0;
        rows.push_back({{"system", "oscar"},
                        {"type", r.type},
                        {"bytes", r.bytes},
                        {"constellation", c},
                        {"security", protection},
                        {"p50_us", s.p50},
                        {"p90_us", s.p90},
                        {"max_us", s.max},
                        {"plain_p50_us", ours.p50},
                        {"ratio_vs_plain", vs_plain},
                        {"samples", s.samples},
                        {"runs", runs.size()}});
        if (!json) {
          std::cout << fmt::format(
                           "{:<17} {:>7} {:<15} {:>9.1f} {:>9.1f} {:>9} {:>9.1f} {:>10} {:>7.2f}  "
                           "(secured, cue topics: {}; ratio to OSCAR without security)\n",
                           r.type, r.bytes, c, s.p50, s.p90, "", s.max, "", vs_plain, protection)
                    << std::flush;
        }
      }
      if (!all) continue;
      auto add = [&](const std::string& system, const Latency& l, std::size_t runs,
                     const std::string& note) {
        if (system != "oscar") {  // OSCAR's row is above, with its ratio
          auto row = system_row(system, type, r, c, l, runs);
          if (!note.empty()) row["config"] = note;
          rows.push_back(row);
        }
        peer_lines.push_back(fmt::format(
            "{:<20} {:<17} {:>7} {:<15} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} {:>7.2f}  {}", system,
            type, r.bytes, c, l.p50, l.p90, l.p99, l.max, ours.p50 > 0 ? l.p50 / ours.p50 : 0,
            note));
      };
      add("oscar", ours, ours_runs.size(), "");
      if (zero_copy) {
        add("iceoryx", raw, raw_runs.size(), "");
      } else {
        add("fastdds", raw, raw_runs.size(), config);
      }
      for (const auto& peer : peers) {
        if (peer_runs.contains(peer.system)) {
          add(peer.system, median_of(peer_runs[peer.system]), peer_runs[peer.system].size(), "");
        }
      }
    }
  }
  if (json) {
    std::cout << nlohmann::json{{"rows", rows}}.dump() << "\n";
  } else if (all) {
    std::cout << fmt::format("\n{:<20} {:<17} {:>7} {:<15} {:>9} {:>9} {:>9} {:>9} {:>7}  {}\n",
                             "system", "type", "bytes", "constell.", "p50 us", "p90 us", "p99 us",
                             "max us", "/oscar", "config");
    for (const auto& line : peer_lines) std::cout << line << "\n";
  }
  roudi.reset();
  if (failures == 0) std::filesystem::remove_all(dir);
  return failures == 0 ? 0 : 1;
}
