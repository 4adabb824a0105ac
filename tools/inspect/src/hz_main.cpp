// oscar hz TOPIC: the rate of a topic and the min, max and standard deviation of the period
// between samples (receive times), over a sliding window, printed once a second.
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <deque>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include <oscar/command_line.hpp>

#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"
#include "raw_tap.hpp"
#include "recorder.hpp"  // topic_of

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

struct Stats {
  std::size_t periods = 0;
  double rate_hz = 0, min_ms = 0, max_ms = 0, std_ms = 0;
};

Stats stats(const std::deque<std::uint64_t>& times) {
  Stats s;
  if (times.size() < 2) return s;
  s.periods = times.size() - 1;
  double sum = 0, sq = 0;
  s.min_ms = 1e300;
  for (std::size_t i = 1; i < times.size(); ++i) {
    const double p = static_cast<double>(times[i] - times[i - 1]) / 1e6;
    sum += p;
    sq += p * p;
    s.min_ms = std::min(s.min_ms, p);
    s.max_ms = std::max(s.max_ms, p);
  }
  const double mean = sum / static_cast<double>(s.periods);
  s.rate_hz = 1000.0 / mean;
  s.std_ms = std::sqrt(std::max(0.0, sq / static_cast<double>(s.periods) - mean * mean));
  return s;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar hz: the rate of a topic and the spread of its period"};
  oscar::SystemOptions tool;
  tool.add_to(app);
  std::string topic_arg;
  std::size_t window = 1000;
  double duration_s = 0, timeout_s = 5;
  app.add_option("TOPIC", topic_arg, "kernel/channel (the cue topic) or a full topic name")
      ->required();
  app.add_option("-w,--window", window, "samples in the sliding window")
      ->check(CLI::Range(2, 1000000));
  app.add_option("--duration", duration_s, "seconds to measure, then print the result and exit");
  app.add_option("--timeout", timeout_s, "seconds to wait for a writer of the topic");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    const auto topic = oscar::record::topic_of(topic_arg);
    auto participant = tool.participant("oscar-hz");
    if (oscar::inspect::wait_for_writer(
            *participant, topic, std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)))
            .empty()) {
      fmt::print(stderr, "oscar hz: no writer of topic '{}' appeared on domain {} within {} s{}\n",
                 topic, participant->domain(), timeout_s,
                 oscar::where_systems_run(participant->domain()));
      return 1;
    }
    std::mutex mutex;
    std::deque<std::uint64_t> times;
    std::uint64_t total = 0;
    oscar::inspect::RawTap tap(*participant, [&](const std::string&, auto, std::uint64_t t) {
      std::lock_guard lock(mutex);
      times.push_back(t);
      ++total;
      if (times.size() > window + 1) times.pop_front();
    });
    tap.subscribe(topic);
    const auto start = std::chrono::steady_clock::now();
    const auto print = [&] {
      std::lock_guard lock(mutex);
      const auto s = stats(times);
      if (s.periods == 0) {
        fmt::print("{}: no samples yet\n", topic);
      } else {
        fmt::print(
            "{}: rate {:.2f} Hz  min {:.3f} ms  max {:.3f} ms  std {:.3f} ms  window {}  total "
            "{}\n",
            topic, s.rate_hz, s.min_ms, s.max_ms, s.std_ms, s.periods, total);
      }
      std::fflush(stdout);
    };
    while (!g_stop) {
      std::this_thread::sleep_for(std::chrono::seconds(1));
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (duration_s > 0 && elapsed >= duration_s) break;
      if (duration_s == 0) print();
    }
    print();
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar hz: %s\n", e.what());
    return 1;
  }
}
