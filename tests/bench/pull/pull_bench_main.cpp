// oscar bench pull: how long a pull of a plain cue from a producer in another process of this host
// takes, answered from the producer's chunks in the consumer (the zero-copy path, a RouDi started
// here) against the same pull over DDS (no RouDi: a request to the producer's frame, which answers
// from its ring), alternating (docs/benchmarks.md, "Pull on one host").
//   oscar bench pull [--types PlainBool,...] [--pulls N] [--runs R] [--json]
// Each run starts the producer (bench_source in an oscar-run, a cue every 10 ms) and a consumer
// (this program with --consume: a module whose bench_sink input pulls), which pulls the newest
// cue N times, 5 ms apart, timing each call from the kernel's side: request to answer in hand.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>
#include <oscar/kernel_registry.hpp>
#include <oscar/module.hpp>
#include <oscar/plain_cue_types.hpp>

#include "peers/peer_list.hpp"  // start_roudi (tests/bench/cueflow)
#include "process.hpp"          // tests/common
#include "zero_copy/chunk_identity.hpp"

namespace {
using namespace std::chrono_literals;
using oscar::test::Process;

std::string bin(const std::string& name) {
  return (std::filesystem::read_symlink("/proc/self/exe").parent_path() / name).string();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

// The consumer: N pulls of the newest cue through `port`, each timed; answers in shared memory
// counted.
template <class T>
nlohmann::json pull(oscar::InputPort& port, int pulls) {
  auto& in = dynamic_cast<oscar::Input<T>&>(port);
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (!in.pull(200ms)) {
    if (std::chrono::steady_clock::now() > until) return {{"error", "no answer within 30 s"}};
  }
  std::vector<double> us;
  int answered = 0, in_shared_memory = 0;
  for (int i = 0; i < pulls; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto cue = in.pull(1s);
    const auto t1 = std::chrono::steady_clock::now();
    if (cue) {
      ++answered;
      us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
      in_shared_memory += oscar::zero_copy::identify_chunk(cue.get()) ? 1 : 0;
    }
    std::this_thread::sleep_for(5ms);
  }
  return {{"asked", pulls},
          {"answered", answered},
          {"in_shared_memory", in_shared_memory},
          {"p50_us", percentile(us, 0.5)},
          {"p90_us", percentile(us, 0.9)},
          {"p99_us", percentile(us, 0.99)},
          {"max_us", us.empty() ? 0 : *std::max_element(us.begin(), us.end())}};
}

int consume(const std::string& type, int pulls, int domain, const std::string& report) {
  oscar::Module module(oscar::ModuleSpec::from_yaml(YAML::Load(fmt::format(R"(
name: puller
mode: deactivated
kernels:
  - type: bench_sink
    name: sink
    params: {{ type: {} }}
    inputs: {{ in: {{ source: src/out, transfer: pull }} }}
)",
                                                                           type)),
                                                    "bench pull"),
                       oscar::plugin_search_path());
  module.start(domain);
  auto& port = *module.kernel("sink").ports().find_input("in");
  const auto result = type == "PlainBool"           ? pull<oscar::PlainBool>(port, pulls)
                      : type == "PlainLineSeg3DSeq" ? pull<oscar::PlainLineSeg3DSeq>(port, pulls)
                                                    : pull<oscar::PlainGvImage>(port, pulls);
  module.stop();
  std::ofstream(report) << result.dump();
  return result.contains("error") ? 1 : 0;
}

// One run: the producer and a consumer, through RouDi if one runs.
nlohmann::json run(const std::string& type, int pulls, int domain, const std::filesystem::path& dir,
                   const std::string& path) {
  const auto report = (dir / fmt::format("{}_{}.json", type, path)).string();
  std::filesystem::remove(report);
  Process producer({bin("oscar-run"), "--name", "src", "--domain", std::to_string(domain), "-k",
                    "bench_source:src", "-p", "src.type=" + type, "-m", "continuous:10ms"},
                   (dir / "producer.log").string());
  Process consumer({bin("oscar-bench-pull"), "--consume", type, "--pulls", std::to_string(pulls),
                    "--domain", std::to_string(domain), "--report", report},
                   (dir / "consumer.log").string());
  const auto code = consumer.wait(180s);
  if (code != 0 || !std::filesystem::exists(report)) {
    return {{"error", fmt::format("consumer {}: {}",
                                  code ? fmt::format("exited with {}", *code) : "did not end",
                                  consumer.output())}};
  }
  return nlohmann::json::parse(std::ifstream(report));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench pull: a pull of a plain cue on one host, zero-copy against DDS"};
  std::vector<std::string> types{"PlainBool", "PlainLineSeg3DSeq", "PlainGvImage"};
  int pulls = 400, runs = 3, domain = 92;
  bool json = false;
  std::string consume_type, report;
  app.add_option("--types", types, "plain cue types to pull")
      ->delimiter(',')
      ->check(CLI::IsMember({"PlainBool", "PlainLineSeg3DSeq", "PlainGvImage"}));
  app.add_option("--pulls", pulls, "timed pulls per run")->check(CLI::PositiveNumber);
  app.add_option("--runs", runs, "runs per type and path, alternating; medians reported")
      ->check(CLI::PositiveNumber);
  app.add_option("--domain", domain, "DDS domain for the run");
  app.add_flag("--json", json, "print JSON instead of a table");
  app.add_option("--consume", consume_type, "(internal) be the consumer of one run")->group("");
  app.add_option("--report", report, "(internal) the consumer's report file")->group("");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  if (!consume_type.empty()) return consume(consume_type, pulls, domain, report);

  const auto dir =
      std::filesystem::temp_directory_path() / fmt::format("oscar_bench_pull_{}", getpid());
  std::filesystem::create_directories(dir);
  nlohmann::json rows = nlohmann::json::array();
  if (!json) {
    std::cout << fmt::format("{:<18} {:<10} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10}\n", "type", "path",
                             "p50 us", "p90 us", "p99 us", "max us", "answered", "in shm");
  }
  int failures = 0;
  for (const auto& type : types) {
    std::map<std::string, std::vector<nlohmann::json>> by_path;
    for (int r = 0; r < runs; ++r) {
      // Alternating which goes first: a machine that slows down does not favour one path.
      const std::vector<std::string> order = r % 2 == 0
                                                 ? std::vector<std::string>{"dds", "zero_copy"}
                                                 : std::vector<std::string>{"zero_copy", "dds"};
      for (const auto& path : order) {
        std::unique_ptr<Process> roudi;
        if (path == "zero_copy" && !(roudi = oscar::bench::start_roudi(dir))) {
          ++failures;
          continue;
        }
        auto result = run(type, pulls, domain, dir, path);
        roudi.reset();  // SIGTERM: it removes its shared memory
        if (result.contains("error")) {
          std::cerr << fmt::format("bench pull: {} {}: {}\n", type, path,
                                   result["error"].get<std::string>());
          ++failures;
          continue;
        }
        by_path[path].push_back(std::move(result));
      }
    }
    for (const auto& [path, results] : by_path) {
      const auto median = [&](const char* key) {
        std::vector<double> v;
        for (const auto& x : results) v.push_back(x[key].get<double>());
        return percentile(v, 0.5);
      };
      int answered = 0, asked = 0, in_shm = 0;
      for (const auto& x : results) {
        answered += x["answered"].get<int>();
        asked += x["asked"].get<int>();
        in_shm += x["in_shared_memory"].get<int>();
      }
      nlohmann::json row = {{"type", type},
                            {"path", path},
                            {"p50_us", median("p50_us")},
                            {"p90_us", median("p90_us")},
                            {"p99_us", median("p99_us")},
                            {"max_us", median("max_us")},
                            {"answered", answered},
                            {"asked", asked},
                            {"in_shared_memory", in_shm},
                            {"runs", results.size()}};
      if (!json) {
        std::cout << fmt::format("{:<18} {:<10} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} {:>9} {:>10}\n",
                                 type, path, median("p50_us"), median("p90_us"), median("p99_us"),
                                 median("max_us"), fmt::format("{}/{}", answered, asked), in_shm);
      }
      rows.push_back(std::move(row));
    }
  }
  if (json) std::cout << nlohmann::json{{"rows", rows}}.dump() << '\n';
  std::filesystem::remove_all(dir);
  return failures == 0 ? 0 : 1;
}
