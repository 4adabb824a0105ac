// oscar topics: every topic with a writer on the domain, its type, QoS and measured rate.
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <oscar/command_line.hpp>

#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"
#include "oscar/topics.hpp"
#include "raw_tap.hpp"

int main(int argc, char** argv) {
  CLI::App app{"oscar topics: the topics of the running system, with types and rates"};
  oscar::SystemOptions tool;
  tool.add_to(app);
  double duration_s = 2;
  bool json = false, all = false;
  app.add_option("--duration", duration_s, "seconds to listen (discovery and rates)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--json", json, "print a JSON array");
  app.add_flag("-a,--all", all, "also OSCAR's own topics (registry, config, log), not only cues");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    auto participant = tool.participant("oscar-topics");
    // Per topic: samples since the first, and when the first came. The rate counts from the
    // first sample, not from the subscription: a reader matched late (a loaded host, a writer
    // discovered late) still measures the writer's rate, not the match time.
    struct Heard {
      std::uint64_t first_ns = 0, after_first = 0;
    };
    std::mutex mutex;
    std::map<std::string, Heard> heard;
    oscar::inspect::RawTap tap(*participant, [&](const std::string& topic, auto, auto at_ns) {
      std::lock_guard lock(mutex);
      auto& h = heard[topic];
      if (h.first_ns == 0) {
        h.first_ns = at_ns;
      } else {
        ++h.after_first;
      }
    });
    const auto wanted = [&](const std::string& t) { return all || oscar::topics::is_cue(t); };
    // Writers discovered at any time while listening are subscribed to.
    const auto total = std::chrono::milliseconds(static_cast<long>(duration_s * 1000));
    const auto end = std::chrono::steady_clock::now() + total;
    while (std::chrono::steady_clock::now() < end) {
      for (const auto& [name, w] : participant->discovered_writers()) {
        if (wanted(name)) tap.subscribe(name);
      }
      std::this_thread::sleep_until(
          std::min(end, std::chrono::steady_clock::now() + std::chrono::milliseconds(100)));
    }
    const auto end_ns = oscar::inspect::now_ns();
    std::map<std::string, Heard> final_heard;
    {
      std::lock_guard lock(mutex);
      final_heard = heard;
    }
    nlohmann::json out = nlohmann::json::array();
    std::size_t width = 5;
    const auto writers = participant->discovered_writers();
    for (const auto& [name, w] : writers) width = std::max(width, wanted(name) ? name.size() : 0);
    if (!json)
      fmt::print("{:<{}}  {:<22}  {:>9}  {}\n", "TOPIC", width, "TYPE", "RATE (Hz)", "QOS");
    for (const auto& [name, w] : writers) {
      if (!wanted(name)) continue;
      const auto& h = final_heard[name];
      const double hz = h.after_first == 0 ? 0
                                           : static_cast<double>(h.after_first) /
                                                 (static_cast<double>(end_ns - h.first_ns) / 1e9);
      if (json) {
        out.push_back({{"topic", name}, {"type", w.type}, {"qos", w.qos}, {"rate_hz", hz}});
      } else {
        fmt::print("{:<{}}  {:<22}  {:>9.1f}  {}\n", name, width, w.type, hz, w.qos);
      }
    }
    if (json) fmt::print("{}\n", out.dump(2));
    if (std::none_of(writers.begin(), writers.end(),
                     [&](const auto& w) { return wanted(w.first); })) {
      fmt::print(stderr, "oscar topics: no {}topic has a writer on domain {} (listened {} s){}\n",
                 all ? "" : "cue ", participant->domain(), duration_s,
                 oscar::where_systems_run(participant->domain()));
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar topics: %s\n", e.what());
    return 1;
  }
}
