// oscar bench bridge: the delay `oscar bridge foxglove` adds, from the moment a cue is made
// (its first stamp) to the moment a Foxglove client is delivered it, for Bool and GvImage cues
// with 1 and 4 clients, and the CPU the bridge costs; beside it `oscar echo` on the same topic,
// run alternately. With --side-channels, rows "Bool+img" too: the Bool clients measured while
// one more client subscribes to a 30 Hz camera's side channels (foxglove.RawImage and
// foxglove.CompressedImage), whose conversion must not delay the raw Bools. Prints a table, or
// JSON (--json). docs/benchmarks.md, "Foxglove bridge".
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>

#include "bridge_clients.hpp"
#include "percentile.hpp"   // tests/common
#include "process.hpp"      // tests/common
#include "process_cpu.hpp"  // tests/common

namespace {
using namespace std::chrono_literals;
using oscar::test::cpu_seconds;
using oscar::test::Process;
using Clock = std::chrono::steady_clock;

struct Type {
  std::string name;
  int period_ms;  // the source's cycle
};

std::string sibling(const std::string& name) {
  return (std::filesystem::read_symlink("/proc/self/exe").parent_path() / name).string();
}

// "2026-11-26T14:47:55.426430520Z" as ns since the Unix epoch.
long long iso_ns(const std::string& iso) {
  std::tm tm{};
  std::istringstream in(iso);
  in >> std::get_time(&tm, "%Y-%m-%dT%H:%M:%S");
  long long ns = static_cast<long long>(timegm(&tm)) * 1'000'000'000LL;
  const auto dot = iso.find('.');
  if (dot != std::string::npos) {
    auto frac = iso.substr(dot + 1, 9);
    frac.resize(9, '0');
    ns += std::stoll(frac);
  }
  return ns;
}

// The delays (µs) `oscar echo` printed: its receive time minus each cue's first stamp.
std::vector<double> echo_delays(const std::string& output) {
  static const std::regex received(R"(received (\S+)Z)"), stamps(R"(stamps: \[([0-9]+))");
  std::vector<double> delays;
  long long at = 0;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, received)) {
      at = iso_ns(m[1]);
    } else if (at != 0 && std::regex_search(line, m, stamps)) {
      delays.push_back(static_cast<double>(at - std::stoll(m[1])) / 1e3);
      at = 0;
    }
  }
  return delays;
}

// The port the bridge says it serves on, once it has said so.
int bridge_port(const Process& bridge, std::chrono::seconds limit) {
  static const std::regex serving(R"(ws://127\.0\.0\.1:([0-9]+))");
  for (const auto until = Clock::now() + limit; Clock::now() < until;) {
    std::smatch m;
    const auto out = bridge.output();
    if (std::regex_search(out, m, serving)) return std::stoi(m[1]);
    std::this_thread::sleep_for(20ms);
  }
  throw std::runtime_error("oscar bridge did not say its port:\n" + bridge.output());
}

// Out of line: inlined into main(), GCC 12 at -O3 takes the copy percentile() sorts for a
// free of a pointer into the middle of a vector (a false -Wfree-nonheap-object).
[[gnu::noinline]] double percentile(const std::vector<double>& samples, double q) {
  return oscar::test::percentile(samples, q);
}

struct Figures {
  std::vector<double> delays_us;
  std::vector<double> after_dds_us;  // of the same cues: from the bridge's DDS take on
  double cpu_pct = 0;
  std::size_t side_messages = 0;  // received by the side channel client
};

class Bench {
 public:
  Bench(int domain, double warmup_s, double seconds, std::string dir)
      : domain_(std::to_string(domain)),
        warmup_(warmup_s),
        seconds_(seconds),
        dir_(std::move(dir)) {}

  // `side_topics`: subscribed by one more client, whose messages are counted, not measured.
  Figures bridge(const std::string& topic, int clients,
                 const std::vector<std::string>& side_topics = {}) {
    Process bridge({sibling("oscar-bridge"), "foxglove", "-d", domain_, "--port", "0"},
                   fmt::format("{}/bridge_{}.log", dir_, ++runs_));
    const int port = bridge_port(bridge, 20s);
    std::atomic<bool> stop{false};
    const auto from = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(warmup_));
    std::vector<oscar::bench::ClientResult> results(static_cast<std::size_t>(clients));
    std::vector<std::thread> threads;
    for (auto& r : results) {
      threads.emplace_back([&, port] { r = oscar::bench::run_client(port, {topic}, from, stop); });
    }
    oscar::bench::ClientResult side;
    if (!side_topics.empty()) {
      threads.emplace_back(
          [&, port] { side = oscar::bench::run_client(port, side_topics, from, stop); });
    }
    std::this_thread::sleep_until(from);
    const double cpu0 = cpu_seconds(bridge.pid());
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds_));
    const double cpu1 = cpu_seconds(bridge.pid());
    stop = true;
    for (auto& t : threads) t.join();
    Figures f;
    f.cpu_pct = (cpu1 - cpu0) / seconds_ * 100;
    for (const auto& r : results) {
      if (!r.error.empty()) throw std::runtime_error("a Foxglove client failed: " + r.error);
      f.delays_us.insert(f.delays_us.end(), r.delays_us.begin(), r.delays_us.end());
      f.after_dds_us.insert(f.after_dds_us.end(), r.after_dds_us.begin(), r.after_dds_us.end());
    }
    if (!side.error.empty())
      throw std::runtime_error("the side channel client failed: " + side.error);
    f.side_messages = side.messages;
    return f;
  }

  Figures echo(const std::string& topic, int period_ms) {
    const auto skip = static_cast<long>(warmup_ * 1000 / period_ms);
    const auto count = skip + static_cast<long>(seconds_ * 1000 / period_ms);
    Process echo({sibling("oscar-echo"), topic, "-d", domain_, "--max-items", "1", "-n",
                  std::to_string(count)},
                 fmt::format("{}/echo_{}.log", dir_, ++runs_));
    if (!echo.wait(std::chrono::seconds(static_cast<long>(warmup_ + seconds_) + 30))) {
      throw std::runtime_error("oscar echo did not receive its cues:\n" + echo.output());
    }
    auto delays = echo_delays(echo.output());
    delays.erase(delays.begin(), delays.begin() + std::min<long>(skip, delays.size()));
    return {delays, {}, 0, 0};
  }

  // A module `name` with one bench_source kernel `name`: topic oscar/cue/<name>/out.
  std::unique_ptr<Process> source(const Type& t, const std::string& name = "src") {
    return std::make_unique<Process>(
        std::vector<std::string>{sibling("oscar-run"), "--name", name, "--domain", domain_, "-k",
                                 "bench_source:" + name, "-p", name + ".type=" + t.name, "-m",
                                 fmt::format("continuous:{}ms", t.period_ms)},
        fmt::format("{}/{}.log", dir_, name));
  }

 private:
  std::string domain_;
  double warmup_, seconds_;
  std::string dir_;
  int runs_ = 0;  // each run's log a file of its own
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench bridge: the delay oscar bridge foxglove adds, beside oscar echo"};
  std::vector<std::string> types{"Bool", "GvImage"};
  std::vector<int> client_counts{1, 4};
  double seconds = 10, warmup = 2;
  int domain = 95, repeat = 1;
  bool json = false, side_channels = false;
  app.add_option("--types", types, "cue types (Bool: 100 Hz, GvImage: 30 Hz)")->delimiter(',');
  app.add_option("--clients", client_counts, "Foxglove clients at once, per row")
      ->delimiter(',')
      ->check(CLI::Range(1, 64));
  app.add_option("--seconds", seconds, "measured seconds per run")->check(CLI::PositiveNumber);
  app.add_option("--warmup", warmup, "seconds left out at the start of each run");
  app.add_option("--repeat", repeat, "runs per row, bridge and echo alternating")
      ->check(CLI::PositiveNumber);
  app.add_option("--domain", domain, "DDS domain for the run")->check(CLI::Range(0, 232));
  app.add_flag("--json", json, "print JSON instead of a table");
  std::vector<std::string> side_channel_topics{"foxglove/cam/out", "foxglove/cam/out/compressed"};
  app.add_option("--side-topics", side_channel_topics,
                 "with --side-channels: the camera's side channels the other client subscribes to")
      ->delimiter(',');
  app.add_flag("--side-channels", side_channels,
               "also Bool rows while another client subscribes to a 30 Hz GvImage's side "
               "channels (foxglove.RawImage and foxglove.CompressedImage)");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  const auto dir =
      std::filesystem::temp_directory_path() / fmt::format("oscar_bench_bridge_{}", getpid());
  std::filesystem::create_directories(dir);
  Bench bench(domain, warmup, seconds, dir.string());
  nlohmann::json rows = nlohmann::json::array();
  if (!json) {
    std::cout << "delays in µs, from the cue's first stamp to its delivery\n"
              << fmt::format("{:<8} {:>7} {:>11} {:>11} {:>13} {:>11} {:>11} {:>9} {:>8}", "type",
                             "clients", "bridge p50", "bridge p99", "after DDS p99", "echo p50",
                             "echo p99", "messages", "CPU %")
              << (side_channels ? "  side msgs/s\n" : "\n");
  }
  try {
    std::vector<std::string> rows_of = types;
    if (side_channels) rows_of.push_back("Bool+img");
    for (const auto& name : rows_of) {
      const bool with_images = name == "Bool+img";
      const Type type{with_images ? "Bool" : name, name == "GvImage" ? 33 : 10};
      const auto topic = std::string("oscar/cue/src/out");
      auto source = bench.source(type);
      std::unique_ptr<Process> camera;
      std::vector<std::string> side_topics;
      if (with_images) {
        camera = bench.source({"GvImage", 33}, "cam");
        side_topics = side_channel_topics;
      }
      std::this_thread::sleep_for(500ms);
      for (const int clients : client_counts) {
        Figures ours, echo;
        for (int i = 1; i <= repeat; ++i) {
          std::cerr << fmt::format("bench bridge: {} with {} client(s), run {}/{}...\n", name,
                                   clients, i, repeat);
          auto b = bench.bridge(topic, clients, side_topics);
          auto e = bench.echo(topic, type.period_ms);
          ours.delays_us.insert(ours.delays_us.end(), b.delays_us.begin(), b.delays_us.end());
          ours.after_dds_us.insert(ours.after_dds_us.end(), b.after_dds_us.begin(),
                                   b.after_dds_us.end());
          ours.cpu_pct += b.cpu_pct / repeat;
          ours.side_messages += b.side_messages;
          echo.delays_us.insert(echo.delays_us.end(), e.delays_us.begin(), e.delays_us.end());
        }
        const double p50 = percentile(ours.delays_us, 0.5), p99 = percentile(ours.delays_us, 0.99);
        const double e50 = percentile(echo.delays_us, 0.5), e99 = percentile(echo.delays_us, 0.99);
        const double a99 = percentile(ours.after_dds_us, 0.99);
        const double side_per_s = static_cast<double>(ours.side_messages) / (seconds * repeat);
        rows.push_back({{"type", name},
                        {"clients", clients},
                        {"bridge_p50_us", p50},
                        {"bridge_p99_us", p99},
                        {"after_dds_p99_us", a99},
                        {"echo_p50_us", e50},
                        {"echo_p99_us", e99},
                        {"messages", ours.delays_us.size()},
                        {"echo_messages", echo.delays_us.size()},
                        {"bridge_cpu_pct", ours.cpu_pct},
                        {"side_messages_per_s", side_per_s}});
        if (!json) {
          std::cout << fmt::format(
                           "{:<8} {:>7} {:>11.0f} {:>11.0f} {:>13.0f} {:>11.0f} {:>11.0f} {:>9} "
                           "{:>8.1f}",
                           name, clients, p50, p99, a99, e50, e99, ours.delays_us.size(),
                           ours.cpu_pct)
                    << (side_channels ? fmt::format(" {:>12.1f}\n", side_per_s) : "\n")
                    << std::flush;
        }
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "bench bridge: " << e.what() << " (logs in " << dir.string() << ")\n";
    return 1;
  }
  if (json) std::cout << nlohmann::json{{"rows", rows}}.dump() << "\n";
  std::filesystem::remove_all(dir);
  return 0;
}
