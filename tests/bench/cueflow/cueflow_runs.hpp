#pragma once
// The runs of `oscar bench cueflow`: its rows (seed 004 Abb. 8's types and figures) and the
// processes of one run — OSCAR's modules, the raw Fast DDS program or a peer, on one host or
// across two test hosts — each returning the consumer's report.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cueflow_report.hpp"
#include "process.hpp"  // tests/common
#include "remote_hosts.hpp"

namespace oscar::bench {

using namespace std::chrono_literals;
using oscar::test::Process;

struct Row {
  std::string type;
  std::size_t bytes;
  double seed_multicore_us, seed_local_us;
  int period_us;
  double seed_remote_us;
};
inline const Row kRows[] = {
    {"Bool", 1, 86, 1736, 2000, 1820},
    {"LineSeg3DSeq", 4800, 254, 5782, 2000, 10544},
    {"GvImage", 442368, 7851, 140157, 10000, 497219},
};

inline std::string bin(const std::string& name) {
  return (std::filesystem::read_symlink("/proc/self/exe").parent_path() / name).string();
}

inline std::optional<Latency> await_report(const std::string& file, std::chrono::seconds limit) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!std::filesystem::exists(file)) {
    if (std::chrono::steady_clock::now() > until) return std::nullopt;
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(20ms);  // written in one go, but let it land
  return parse_report(nlohmann::json::parse(std::ifstream(file)));
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

  // The zero-copy constellation (docs/zero_copy.md): the row's plain type ("Plain" + its type)
  // between two modules on this host with a RouDi running. The source starts first, so that the
  // sink finds its output offered in shared memory; a run whose sink does not say its cues come
  // zero-copy gives no figure.
  std::optional<Latency> framework_zero_copy(const Row& r) {
    const auto type = "Plain" + r.type;
    const auto report = file("oscar_zero_copy", r, false);
    std::vector<std::unique_ptr<Process>> procs;
    procs.push_back(std::make_unique<Process>(
        std::vector<std::string>{bin("oscar-run"), "--name", "src", "--domain", dom(), "-k",
                                 "bench_source:src", "-p", "src.type=" + type, "-m",
                                 fmt::format("continuous:{}us", r.period_us)},
        log("zero_copy_src")));
    std::this_thread::sleep_for(500ms);  // its output offered through RouDi
    procs.push_back(std::make_unique<Process>(
        std::vector<std::string>{
            bin("oscar-run"), "--name", "sink", "--domain", dom(), "-k", "bench_sink:sink", "-p",
            "sink.type=" + type, "-p", "sink.report=" + report, "-p",
            fmt::format("sink.expect={}", count_ + warmup_), "-p",
            fmt::format("sink.warmup={}", warmup_), "-i", "sink.in=src/out", "-m", "single_step"},
        log("zero_copy_sink")));
    auto latency = await_report(report, limit(r));
    if (latency && procs.back()->output().find("come zero-copy") == std::string::npos) {
      std::cerr << fmt::format("bench cueflow: {}: the sink's cues did not come zero-copy: {}\n",
                               type, procs.back()->output());
      return std::nullopt;
    }
    return latency;
  }

  // One run of a minimal program (oscar-bench-raw or a peer; `args` its configuration): `both`
  // for the multicore constellation, else `sub` and, 300 ms later, `pub`. `count` overrides the
  // measured cues (the pre-pass runs fewer).
  std::optional<Latency> program(const std::string& name, const std::vector<std::string>& args,
                                 const Row& r, bool multicore, int count = 0) {
    if (count == 0) count = count_;
    const auto report = file(name.c_str(), r, multicore);
    auto common = join(row_args(r), args, {});
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
    const auto common = row_args(r);
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

  // A peer's program across the test hosts: subscriber on host 2, publisher on host 1, each on
  // its host's address only (oscar-bench-cyclonedds' --address, --peer).
  std::optional<Latency> peer_remote(const std::string& program, const Row& r,
                                     const oscar::bench::RemoteHosts& hosts) {
    const auto report = remote_file(program.c_str(), r);
    const auto reach = [&](int i) {
      return std::vector<std::string>{"--address",
                                      hosts.address(i),
                                      "--peer",
                                      hosts.address(1),
                                      "--peer",
                                      hosts.address(2),
                                      "--udp-buffer-bytes",
                                      std::to_string(hosts.udp_buffer_bytes())};
    };
    const auto common = row_args(r);
    const std::vector<std::string> sub{"sub",
                                       "--report",
                                       report,
                                       "--expect",
                                       std::to_string(count_ + warmup_),
                                       "--warmup",
                                       std::to_string(warmup_)};
    const std::vector<std::string> pub{"pub", "--count", std::to_string(10 * (count_ + warmup_))};
    return across(r, hosts, report,
                  join(hosts.on(2), {bin(program.c_str())}, join(sub, common, reach(2))),
                  join(hosts.on(1), {bin(program.c_str())}, join(pub, common, reach(1))));
  }

 private:
  // What every program of a row is told: the type, the domain, the publishing period.
  std::vector<std::string> row_args(const Row& r) {
    return {"--type", r.type, "--domain", dom(), "--period-us", std::to_string(r.period_us)};
  }

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

/// Issue 21 item 5 (throughput.cpp): per row of `types` and constellation (multicore, local),
/// the highest rate without loss over `seconds`, OSCAR beside raw Fast DDS; a table or JSON on
/// standard output. Returns the exit code.
int run_throughput(const std::vector<std::string>& types,
                   const std::vector<std::string>& constellations, double seconds, int domain,
                   const std::string& dir, bool json);

}  // namespace oscar::bench
