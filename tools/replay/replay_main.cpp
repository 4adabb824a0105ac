// `oscar replay FILE [--rate R] [--loop] [--start T] [--end T] [--topics ...] [--remap a:=b]
//  [--step]`: republishes a recording with its original relative timing; docs/recording.md.
#include <unistd.h>

#include <csignal>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/process_util.hpp"
#include "oscar/registry/system_options.hpp"
#include "recorder.hpp"  // topic_of
#include "replayer.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// "2.5" or "2.5s", "1500ms", "1m" -> duration.
std::chrono::nanoseconds parse_time(const std::string& option, const std::string& s) {
  std::size_t used = 0;
  double v = -1;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
  }
  const std::string unit = s.substr(std::min(used, s.size()));
  const double seconds = unit == "ms"                  ? 1e-3
                         : unit == "s" || unit.empty() ? 1
                         : unit == "m"                 ? 60
                                                       : -1;
  if (seconds < 0 || v < 0) {
    throw std::invalid_argument(option + " '" + s +
                                "': expected a time from the recording's "
                                "start like 2.5s, 1500ms or 1m");
  }
  return std::chrono::nanoseconds(static_cast<std::int64_t>(v * seconds * 1e9));
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Republishes an MCAP recording with its original relative timing"};
  app.name("oscar replay");
  oscar::replay::ReplayOptions o;
  std::string start, end;
  std::vector<std::string> remaps;
  app.add_option("FILE", o.file, "MCAP file")->required();
  app.add_option("--rate", o.rate, "speed factor (2 = twice as fast)")->capture_default_str();
  app.add_flag("--loop", o.loop, "start again at the end");
  app.add_option("--start", start, "begin this far into the recording (e.g. 2.5s)");
  app.add_option("--end", end, "stop this far into the recording");
  app.add_option("--topics", o.topics, "topics or globs to replay (default: all)");
  app.add_option("--remap", remaps, "FROM:=TO publish topic FROM as TO");
  app.add_flag("--step", o.step, "publish one message per Enter");
  oscar::SystemOptions system;
  system.add_domain_to(app);
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  oscar::keep_cue_memory_in_process();
  try {
    o.domain = system.resolved_domain();
    if (!start.empty()) o.start = parse_time("--start", start);
    if (!end.empty()) o.end = parse_time("--end", end);
    for (const auto& r : remaps) {
      const auto at = r.find(":=");
      if (at == std::string::npos || at == 0 || at + 2 == r.size()) {
        throw std::invalid_argument("--remap '" + r + "': expected FROM:=TO");
      }
      o.remap[oscar::record::topic_of(r.substr(0, at))] = oscar::record::topic_of(r.substr(at + 2));
    }
    o.progress = isatty(STDERR_FILENO) && !o.step;
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    oscar::replay::Replayer replayer(o);
    const auto c = replayer.run(g_stop);
    fmt::print("published {} messages on {} topics in {:.3f} s\n", c.published, c.topics,
               c.seconds);
    if (!o.step && c.published > 0) {
      fmt::print("publishing began late by p50 {:.0f} us, p99 {:.0f} us, max {:.0f} us\n",
                 c.late_us_p50, c.late_us_p99, c.late_us_max);
    }
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "oscar replay: {}\n", e.what());
    return 1;
  }
}
