// oscar bench cueflow: seed 004 Abb. 8 (cue transfer time of Bool, LineSeg3DSeq with 100 lines
// and a 768x576 GvImage) for the multi-core, local and remote constellations, against raw Fast
// DDS with the same type and QoS, measured in the same run: multi-core and local in its fastest
// configuration (a pre-pass tries delivery, publish mode and transport per row), remote over UDP
// between two test hosts. --all adds the peers (Fast DDS data sharing, Cyclone DDS, iceoryx, a
// memcpy + futex floor) to the multi-core and local rows, each its own program in peers/. Prints
// a table, or JSON (--json). docs/benchmarks.md explains the rows.
#include <sys/resource.h>

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
#include "peers/peer_list.hpp"
#include "process.hpp"  // tests/common
#include "remote_hosts.hpp"

namespace {
using namespace std::chrono_literals;
using oscar::test::Process;

struct Row {
  std::string type;
  std::size_t bytes;
  double seed_multicore_us, seed_local_us;
  int period_us;
  double seed_remote_us;
};
const Row kRows[] = {
    {"Bool", 1, 86, 1736, 2000, 1820},
    {"LineSeg3DSeq", 4800, 254, 5782, 2000, 10544},
    {"GvImage", 442368, 7851, 140157, 10000, 497219},
};

using oscar::bench::kPeers;
using oscar::bench::Latency;
using oscar::bench::median_of;
using oscar::bench::Peer;
using oscar::bench::start_roudi;

std::string bin(const std::string& name) {
  return (std::filesystem::read_symlink("/proc/self/exe").parent_path() / name).string();
}

std::optional<Latency> await_report(const std::string& file, std::chrono::seconds limit) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!std::filesystem::exists(file)) {
    if (std::chrono::steady_clock::now() > until) return std::nullopt;
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(20ms);  // written in one go, but let it land
  return oscar::bench::parse_report(nlohmann::json::parse(std::ifstream(file)));
}

class Bench {
 public:
  Bench(int count, int warmup, int domain, std::string dir)
      : count_(count), warmup_(warmup), domain_(domain), dir_(std::move(dir)) {}

  // With a `keystore`, both modules authenticate as their identities in it (module.src and
  // module.sink) and their cue topic is protected as its governance says.
  std::optional<Latency> framework(const Row& r, bool multicore, const std::string& keystore = "") {
    const auto report = file(keystore.empty() ? "oscar" : "oscar_secured", r, multicore);
    const std::vector<std::string> sink{"-k", "bench_sink:sink",
                                        "-p", "sink.type=" + r.type,
                                        "-p", "sink.report=" + report,
                                        "-p", fmt::format("sink.expect={}", count_ + warmup_),
                                        "-p", fmt::format("sink.warmup={}", warmup_),
                                        "-i", "sink.in=src/out"};
    const std::vector<std::string> source{"-k", "bench_source:src", "-p", "src.type=" + r.type};
    const auto cycle = fmt::format("continuous:{}us", r.period_us);
    std::vector<std::unique_ptr<Process>> procs;
    if (multicore) {
      auto args = join({bin("oscar-run"), "--name", "bench", "--domain", dom()}, source, sink);
      args.insert(args.end(), {"-m", cycle});
      procs.push_back(std::make_unique<Process>(args, log("multicore")));
    } else {
      std::vector<std::string> run{bin("oscar-run")};
      if (!keystore.empty()) run = {"/usr/bin/env", "OSCAR_KEYSTORE=" + keystore, bin("oscar-run")};
      auto s =
          join(join(run, {"--name", "sink", "--domain", dom()}, {}), sink, {"-m", "single_step"});
      procs.push_back(std::make_unique<Process>(s, log("sink")));
      std::this_thread::sleep_for(keystore.empty() ? 300ms : 1000ms);  // + authentication
      auto p = join(join(run, {"--name", "src", "--domain", dom()}, {}), source, {"-m", cycle});
      procs.push_back(std::make_unique<Process>(p, log("src")));
    }
    return await_report(report, limit(r));
  }

  // One run of a minimal program (oscar-bench-raw or a peer; `args` its configuration): `both`
  // for the multicore constellation, else `sub` and, 300 ms later, `pub`. `count` overrides the
  // measured cues (the pre-pass runs fewer).
  std::optional<Latency> program(const std::string& name, const std::vector<std::string>& args,
                                 const Row& r, bool multicore, int count = 0) {
    if (count == 0) count = count_;
    const auto report = file(name.c_str(), r, multicore);
    auto common =
        join({"--type", r.type, "--domain", dom(), "--period-us", std::to_string(r.period_us)},
             args, {});
    const std::vector<std::string> sub{"--report", report,
                                       "--expect", std::to_string(count + warmup_),
                                       "--warmup", std::to_string(warmup_)};
    const std::vector<std::string> pub{"--count", std::to_string(10 * (count + warmup_))};
    std::vector<std::unique_ptr<Process>> procs;
    if (multicore) {
      procs.push_back(std::make_unique<Process>(
          join(join({bin(name), "both"}, common, sub), pub, {}), log(name + "_both")));
    } else {
      procs.push_back(
          std::make_unique<Process>(join({bin(name), "sub"}, common, sub), log(name + "_sub")));
      std::this_thread::sleep_for(300ms);
      procs.push_back(
          std::make_unique<Process>(join({bin(name), "pub"}, common, pub), log(name + "_pub")));
    }
    return await_report(report, limit(r, count));
  }

  // The remote constellation: the sink on host 2, the source on host 1 (remote_hosts.hpp). Each
  // run checks that the cues crossed the veth into host 2, so not by shared memory.
  std::optional<Latency> framework_remote(const Row& r, const oscar::bench::RemoteHosts& hosts) {
    const auto report = remote_file("oscar", r);
    const auto sink = fmt::format(
        "{{name: sink, network: {}, mode: single_step, kernels: [{{type: bench_sink, name: sink, "
        "inputs: {{in: src/out}}, params: {{type: {}, report: '{}', expect: {}, warmup: {}}}}}]}}",
        hosts.network(2), r.type, report, count_ + warmup_, warmup_);
    const auto source = fmt::format(
        "{{name: src, network: {}, mode: {{continuous: {}us}}, kernels: [{{type: bench_source, "
        "name: src, params: {{type: {}}}}}]}}",
        hosts.network(1), r.period_us, r.type);
    const auto sink_file = dir_ + "/remote_sink.yaml", source_file = dir_ + "/remote_src.yaml";
    std::ofstream(sink_file) << sink << "\n";
    std::ofstream(source_file) << source << "\n";
    return across(r, hosts, report,
                  join(hosts.on(2), {bin("oscar-run"), sink_file, "--domain", dom()}, {}),
                  join(hosts.on(1), {bin("oscar-run"), source_file, "--domain", dom()}, {}));
  }

  std::optional<Latency> raw_remote(const Row& r, const oscar::bench::RemoteHosts& hosts) {
    const auto report = remote_file("raw", r);
    const std::vector<std::string> common{"--type", r.type,        "--domain",
                                          dom(),    "--period-us", std::to_string(r.period_us)};
    const std::vector<std::string> sub{"sub",
                                       "--report",
                                       report,
                                       "--expect",
                                       std::to_string(count_ + warmup_),
                                       "--warmup",
                                       std::to_string(warmup_),
                                       "--network",
                                       hosts.network(2)};
    const std::vector<std::string> pub{"pub", "--count", std::to_string(10 * (count_ + warmup_)),
                                       "--network", hosts.network(1)};
    return across(r, hosts, report,
                  join(hosts.on(2), {bin("oscar-bench-raw")}, join(sub, common, {})),
                  join(hosts.on(1), {bin("oscar-bench-raw")}, join(pub, common, {})));
  }

 private:
  std::optional<Latency> across(const Row& r, const oscar::bench::RemoteHosts& hosts,
                                const std::string& report, const std::vector<std::string>& sink,
                                const std::vector<std::string>& source) {
    const auto before = hosts.received(2);
    std::vector<std::unique_ptr<Process>> procs;
    procs.push_back(std::make_unique<Process>(sink, log("remote_sink")));
    std::this_thread::sleep_for(300ms);
    procs.push_back(std::make_unique<Process>(source, log("remote_src")));
    auto latency = await_report(report, limit(r));
    procs.clear();
    const auto after = hosts.received(2);
    const auto cues = static_cast<std::uint64_t>(count_ + warmup_);
    if (latency &&
        (after.packets - before.packets < cues || after.bytes - before.bytes < cues * r.bytes)) {
      std::cerr << fmt::format(
          "bench cueflow: {} remote: only {} packets, {} bytes came into host 2 for {} cues: not "
          "over UDP\n",
          r.type, after.packets - before.packets, after.bytes - before.bytes, cues);
      return std::nullopt;
    }
    return latency;
  }
  std::string remote_file(const char* who, const Row& r) {
    auto f = fmt::format("{}/{}_{}_remote.json", dir_, who, r.type);
    std::filesystem::remove(f);
    return f;
  }
  static std::vector<std::string> join(std::vector<std::string> a,
                                       const std::vector<std::string>& b,
                                       const std::vector<std::string>& c) {
    a.insert(a.end(), b.begin(), b.end());
    a.insert(a.end(), c.begin(), c.end());
    return a;
  }
  std::string dom() const { return std::to_string(domain_); }
  std::string file(const char* who, const Row& r, bool multicore) {
    auto f = fmt::format("{}/{}_{}_{}.json", dir_, who, r.type, multicore ? "multicore" : "local");
    std::filesystem::remove(f);
    return f;
  }
  std::string log(const std::string& who) const { return fmt::format("{}/{}.log", dir_, who); }
  std::chrono::seconds limit(const Row& r, int count = 0) const {
    return std::chrono::seconds(30 +
                                ((count ? count : count_) + warmup_) * r.period_us / 1'000'000 * 3);
  }
  int count_, warmup_, domain_;
  std::string dir_;
};

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

nlohmann::json system_row(const std::string& system, const Row& r, const std::string& c,
                          const Latency& l, std::size_t runs) {
  return {{"system", system},     {"type", r.type},  {"bytes", r.bytes}, {"constellation", c},
          {"p50_us", l.p50},      {"p90_us", l.p90}, {"p99_us", l.p99},  {"max_us", l.max},
          {"samples", l.samples}, {"runs", runs}};
}

// Issue 21 item 5: per row, the highest rate at which a trial of `seconds` (after a second of
// warm-up) loses no cue, OSCAR beside raw Fast DDS (listener, synchronous, shared memory), and
// the CPU % of that trial's processes (user + system over the trial's wall time, start-up
// included; 100 = one core). Multicore and local only.
int run_throughput(const std::vector<std::string>& types,
                   const std::vector<std::string>& constellations, double seconds, int domain,
                   const std::string& dir, bool json) {
  const auto trial = [&](const Row& r, bool multicore, bool raw) {
    return [&, r, multicore, raw](double rate) -> std::optional<oscar::bench::Trial> {
      Row at = r;
      at.period_us = std::max(1, static_cast<int>(std::lround(1e6 / rate)));
      const int n = static_cast<int>(rate * seconds), warm = static_cast<int>(rate);
      Bench b(n, warm, domain, dir);
      rusage before{}, after{};
      getrusage(RUSAGE_CHILDREN, &before);
      const auto start = std::chrono::steady_clock::now();
      const auto l =
          raw ? b.program("oscar-bench-raw", oscar::bench::raw_config_args("listener,sync,shm"), at,
                          multicore)
              : b.framework(at, multicore);
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      getrusage(RUSAGE_CHILDREN, &after);
      const auto cpu_s = [](const rusage& u) {
        return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
               static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
      };
      const bool lossless = l && l->gaps == 0 && l->samples >= n;
      std::cerr << fmt::format("bench cueflow: throughput {} {} {} at {:.0f} Hz: {}\n", r.type,
                               multicore ? "multicore" : "local", raw ? "raw" : "oscar", rate,
                               !l         ? "no report"
                               : lossless ? "no loss"
                                          : fmt::format("{} lost", l->gaps));
      if (!lossless) return std::nullopt;
      return oscar::bench::Trial{(cpu_s(after) - cpu_s(before)) / wall * 100, l->rate_hz()};
    };
  };
  nlohmann::json rows = nlohmann::json::array();
  if (!json) {
    std::cout << fmt::format(
        "highest rate asked for that lost no cue over {:g} s, the rate the cues came at, and the "
        "CPU of that trial\n{:<13} {:<10} {:>9} {:>9} {:>6} {:>9} {:>9} {:>6}\n",
        seconds, "type", "constell.", "oscar Hz", "came Hz", "CPU %", "raw Hz", "came Hz", "CPU %");
  }
  for (const auto& r : kRows) {
    if (std::find(types.begin(), types.end(), r.type) == types.end()) continue;
    for (const auto& c : constellations) {
      if (c == "remote") continue;
      const bool multicore = c == "multicore";
      const double start = 1e6 / r.period_us, cap = start * 128;
      const auto ours =
          oscar::bench::highest_lossless_rate(start, cap, 3, trial(r, multicore, false));
      const auto raw =
          oscar::bench::highest_lossless_rate(start, cap, 3, trial(r, multicore, true));
      for (const auto& [system, t] : {std::pair{"oscar", ours}, std::pair{"fastdds", raw}}) {
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
                         "{:<13} {:<10} {:>9.0f} {:>9.0f} {:>6.1f} {:>9.0f} {:>9.0f} {:>6.1f}\n",
                         r.type, c, ours.rate_hz, ours.at.achieved_hz, ours.at.cpu_pct, raw.rate_hz,
                         raw.at.achieved_hz, raw.at.cpu_pct)
                  << std::flush;
      }
    }
  }
  if (json) std::cout << nlohmann::json{{"throughput", rows}}.dump() << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench cueflow: one-way cue latency, OSCAR vs raw Fast DDS (seed 004 Abb. 8)"};
  bool json = false, all = false;
  int count = 1000, warmup = 50, domain = 90, repeat = 3, prepass = 200;
  std::string raw_config = "auto";
  std::vector<std::string> types{"Bool", "LineSeg3DSeq", "GvImage"};
  std::vector<std::string> constellations{"multicore", "local", "remote"};
  app.add_flag("--json", json, "print JSON instead of a table");
  app.add_option("--count", count, "measured cues per row (after the warm-up)")
      ->check(CLI::PositiveNumber);
  app.add_option("--warmup", warmup, "cues left out at the start of each row");
  app.add_option("--domain", domain, "DDS domain for the run");
  app.add_option("--repeat", repeat, "runs per row, OSCAR and raw alternating; medians reported")
      ->check(CLI::PositiveNumber);
  app.add_option("--types", types, "rows to run")->delimiter(',');
  app.add_option("--constellations", constellations,
                 "multicore, local, remote (two test hosts in network namespaces; root)")
      ->delimiter(',')
      ->check(CLI::IsMember({"multicore", "local", "remote"}));
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
                 "trial (multicore and local), OSCAR beside raw Fast DDS, and its CPU")
      ->check(CLI::PositiveNumber);
  bool security = false;
  app.add_flag("--security", security,
               "local rows also with DDS Security (keystores made here), cue topics unprotected, "
               "signed and encrypted, alternated with the plain runs");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  const auto dir = std::filesystem::temp_directory_path() / fmt::format("oscar_bench_{}", getpid());
  std::filesystem::create_directories(dir);
  if (throughput_s > 0) {
    const int code =
        run_throughput(types, constellations, throughput_s, domain, dir.string(), json);
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
  std::unique_ptr<Process> roudi;
  for (const auto& peer : all ? std::span(kPeers) : std::span<const Peer>()) {
    if (!std::filesystem::exists(bin(peer.program))) {
      std::cerr << fmt::format("bench cueflow: {} not built (its package missing), no {} rows\n",
                               peer.program, peer.system);
    } else if (peer.system != std::string("iceoryx") || (roudi = start_roudi(dir))) {
      peers.push_back(peer);
    }
  }
  nlohmann::json rows = nlohmann::json::array();
  std::vector<std::string> peer_lines;
  int failures = 0;
  if (!json) {
    std::cout << fmt::format(
        "{:<13} {:>7} {:<10} {:>9} {:>9} {:>9} {:>9} {:>10} {:>7} {:>10}  {}\n", "type", "bytes",
        "constell.", "p50 us", "p90 us", "p99 us", "max us", "raw p50", "ratio", "seed us",
        "raw config");
  }
  for (const auto& r : kRows) {
    if (std::find(types.begin(), types.end(), r.type) == types.end()) continue;
    for (const auto& c : constellations) {
      const bool multicore = c == "multicore", remote = c == "remote";
      // Remote: the raw program over the test hosts' UDP, in Fast DDS's default configuration.
      std::string config = remote ? "listener,sync,udp" : raw_config;
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
      const auto raw_args = oscar::bench::raw_config_args(config);
      std::vector<Latency> ours_runs, raw_runs;
      std::map<std::string, std::vector<Latency>> secured_runs;  // by cue protection
      std::map<std::string, std::vector<Latency>> peer_runs;     // by system
      for (int i = 1; i <= repeat; ++i) {
        std::cerr << fmt::format("bench cueflow: {} {} run {}/{} ({} cues)...\n", r.type, c, i,
                                 repeat, count);
        const auto o = remote ? bench.framework_remote(r, *hosts) : bench.framework(r, multicore);
        const auto w = remote ? bench.raw_remote(r, *hosts)
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
             multicore || remote ? decltype(keystores){} : keystores) {
          if (const auto s = bench.framework(r, false, keystore)) {
            secured_runs[protection].push_back(*s);
          } else {
            std::cerr << fmt::format("bench cueflow: {} {} secured ({}): no report (logs in {})\n",
                                     r.type, c, protection, dir.string());
            ++failures;
          }
        }
        for (const auto& peer : remote ? std::vector<Peer>{} : peers) {  // on one host only
          if (const auto l = bench.program(peer.program, {}, r, multicore)) {
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
                      {"type", r.type},
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
                      {"raw_config", config},
                      {"ratio", ratio},
                      {"samples", ours.samples},
                      {"runs", ours_runs.size()},
                      {"seed_us", seed}});
      if (!json) {
        std::cout << fmt::format(
                         "{:<13} {:>7} {:<10} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} {:>10.1f} "
                         "{:>7.2f} {:>10.0f}  {}\n",
                         r.type, r.bytes, c, ours.p50, ours.p90, ours.p99, ours.max, raw.p50, ratio,
                         seed, config)
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
                           "{:<13} {:>7} {:<10} {:>9.1f} {:>9.1f} {:>9} {:>9.1f} {:>10} {:>7.2f}  "
                           "(secured, cue topics: {}; ratio to OSCAR without security)\n",
                           r.type, r.bytes, c, s.p50, s.p90, "", s.max, "", vs_plain, protection)
                    << std::flush;
        }
      }
      if (!all) continue;
      auto add = [&](const std::string& system, const Latency& l, std::size_t runs,
                     const std::string& note) {
        if (system != "oscar") {  // OSCAR's row is above, with its ratio
          auto row = system_row(system, r, c, l, runs);
          if (!note.empty()) row["config"] = note;
          rows.push_back(row);
        }
        peer_lines.push_back(fmt::format(
            "{:<20} {:<13} {:>7} {:<10} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} {:>7.2f}  {}", system,
            r.type, r.bytes, c, l.p50, l.p90, l.p99, l.max, ours.p50 > 0 ? l.p50 / ours.p50 : 0,
            note));
      };
      add("oscar", ours, ours_runs.size(), "");
      add("fastdds", raw, raw_runs.size(), config);
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
    std::cout << fmt::format("\n{:<20} {:<13} {:>7} {:<10} {:>9} {:>9} {:>9} {:>9} {:>7}  {}\n",
                             "system", "type", "bytes", "constell.", "p50 us", "p90 us", "p99 us",
                             "max us", "/oscar", "config");
    for (const auto& line : peer_lines) std::cout << line << "\n";
  }
  roudi.reset();
  if (failures == 0) std::filesystem::remove_all(dir);
  return failures == 0 ? 0 : 1;
}
