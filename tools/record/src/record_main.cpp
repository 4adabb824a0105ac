// `oscar record [-o FILE] [TOPIC|GLOB ...|--all] [--compression zstd|lz4|none]
//  [--split-size N] [--split-duration D]`: records cue topics to MCAP; docs/recording.md.
#include <unistd.h>

#include <csignal>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/registry/system_options.hpp"
#include "recorder.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// "512M", "2G", "1000" -> bytes.
std::uint64_t parse_size(const std::string& s) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    v = -1;
  }
  const std::string unit = s.substr(used);
  const double factor = unit.empty() || unit == "B"    ? 1
                        : unit == "K" || unit == "KiB" ? 1024.0
                        : unit == "M" || unit == "MiB" ? 1048576.0
                        : unit == "G" || unit == "GiB" ? 1073741824.0
                                                       : -1;
  if (factor < 0 || v <= 0) {
    throw std::invalid_argument("--split-size '" + s + "': expected a positive size like 500M");
  }
  return static_cast<std::uint64_t>(v * factor);
}

// "30s", "5m", "1h", "250ms" -> duration.
std::chrono::nanoseconds parse_duration(const std::string& s) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    v = -1;
  }
  const std::string unit = s.substr(used);
  const double seconds = unit == "ms"                  ? 1e-3
                         : unit == "s" || unit.empty() ? 1
                         : unit == "m"                 ? 60
                         : unit == "h"                 ? 3600
                                                       : -1;
  if (seconds < 0 || v <= 0) {
    throw std::invalid_argument("--split-duration '" + s +
                                "': expected a positive duration like 30s, "
                                "5m or 1h");
  }
  return std::chrono::nanoseconds(static_cast<std::int64_t>(v * seconds * 1e9));
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Records cue topics to an MCAP file (types need not be known)"};
  app.name("oscar record");
  oscar::record::RecorderOptions o;
  std::string compression = "zstd", split_size, split_duration;
  app.add_option("-o,--output", o.output, "MCAP file to write")->capture_default_str();
  app.add_option("TOPIC", o.topics, "topics or globs ('src/out' = oscar/cue/src/out)");
  app.add_flag("--all", o.all, "record every cue topic");
  app.add_option("--compression", compression, "zstd, lz4 or none")->capture_default_str();
  app.add_option("--split-size", split_size, "start a new file after this size (e.g. 500M)");
  app.add_option("--split-duration", split_duration, "start a new file after this time (e.g. 5m)");
  oscar::SystemOptions system;
  system.add_domain_to(app);
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    o.domain = system.resolved_domain();
    o.compression = oscar::mcap::parse_compression(compression);
    if (!split_size.empty()) o.split_size_bytes = parse_size(split_size);
    if (!split_duration.empty()) o.split_duration = parse_duration(split_duration);
    o.progress = isatty(STDERR_FILENO);
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    oscar::record::Recorder recorder(o);
    recorder.run(g_stop);
    const auto c = recorder.counters();
    fmt::print("received {}, written {}, dropped {} ({:.1f} MB)\n", c.received, c.written,
               c.dropped, c.bytes / 1e6);
    for (const auto& f : recorder.files()) fmt::print("wrote {}\n", f);
    return c.dropped == 0 ? 0 : 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "oscar record: {}\n", e.what());
    return 1;
  }
}
