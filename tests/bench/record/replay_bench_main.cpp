// oscar bench replay: writes an MCAP file with the five streams of issue 4 on an exact schedule
// (four 30 Hz GvImage, one 1 kHz Bool), replays it with an oscar-replay child and measures, for
// every cue received here, how far its arrival is from the original schedule: the error of
// (arrival - log time) against its median over all cues (the replay's start is a free shift).
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "cue_header_cdr.hpp"  // tools/record
#include "idl_texts.hpp"       // tools/record
#include "oscar/cue_type_info.hpp"
#include "oscar/mcap/writer.hpp"
#include "oscar/process_util.hpp"
#include "process.hpp"  // tests/common
#include "raw_tap.hpp"  // tools/inspect

namespace {
using namespace std::chrono_literals;

// Writes the schedule; returns (topic, seq) -> log time.
std::map<std::pair<std::string, std::uint64_t>, std::uint64_t> write_file(const std::string& path,
                                                                          double seconds,
                                                                          int cameras) {
  oscar::mcap::WriterOptions o;
  o.compression = oscar::mcap::Compression::kNone;
  oscar::mcap::Writer w(path, o);
  const auto schema_of = [&](const std::string& type) {
    const auto& idl = oscar::record::idl_texts().at(type);
    return w.add_schema(type, "omgidl", {idl.begin(), idl.end()});
  };
  const auto image_schema = schema_of("oscar::GvImage");
  const auto bool_schema = schema_of("oscar::Bool");
  const auto streams = oscar::bench::streams(cameras);
  std::vector<std::uint16_t> channels;
  for (const auto& s : streams) {
    channels.push_back(w.add_channel(s.image ? image_schema : bool_schema,
                                     "oscar/cue/" + s.kernel + "/out", "cdr",
                                     {{"type", s.image ? "oscar::GvImage" : "oscar::Bool"}}));
  }
  // Messages in time order, as a recording holds them.
  struct Due {
    std::uint64_t t;
    std::size_t stream;
    std::uint64_t seq;
  };
  std::vector<Due> due;
  const std::uint64_t t0 = 1'000'000'000'000'000'000ull;
  const auto end = t0 + static_cast<std::uint64_t>(seconds * 1e9);
  for (std::size_t i = 0; i < streams.size(); ++i) {
    std::uint64_t seq = 1;
    for (auto t = t0; t < end; t += static_cast<std::uint64_t>(streams[i].period.count()))
      due.push_back({t, i, seq++});
  }
  std::sort(due.begin(), due.end(), [](const Due& a, const Due& b) { return a.t < b.t; });
  auto image = oscar::bench::pal_image();
  oscar::Bool b;
  std::map<std::pair<std::string, std::uint64_t>, std::uint64_t> schedule;
  for (const auto& d : due) {
    const auto& s = streams[d.stream];
    auto& h = s.image ? image.header() : b.header();
    h.seq(d.seq);
    h.source(s.kernel + "/out");
    h.stamps({d.t});
    const auto bytes = s.image ? oscar::cue_type_info<oscar::GvImage>().serialize(&image)
                               : oscar::cue_type_info<oscar::Bool>().serialize(&b);
    oscar::mcap::MessageView m;
    m.channel_id = channels[d.stream];
    m.sequence = static_cast<std::uint32_t>(d.seq);
    m.log_time = m.publish_time = d.t;
    m.data = bytes;
    w.write(m);
    schedule[{"oscar/cue/" + s.kernel + "/out", d.seq}] = d.t;
  }
  w.close();
  return schedule;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench replay: timing error of replayed cues against the original schedule"};
  bool json = false;
  std::string out_dir = "/tmp/oscar-bench-replay";
  double duration_s = 10;
  int domain = 229;
  int cameras = 4;
  app.add_flag("--json", json, "print {timing_err_us_p50, timing_err_us_p99}");
  app.add_option("--out-dir", out_dir, "where the MCAP file is written (and kept)");
  app.add_option("--duration", duration_s, "seconds of recording to replay")
      ->check(CLI::PositiveNumber);
  app.add_option("--cameras", cameras, "30 Hz GvImage streams beside the 1 kHz Bool (0..4)")
      ->check(CLI::Range(0, 4));
  app.add_option("-d,--domain", domain, "DDS domain");
  CLI11_PARSE(app, argc, argv);
  oscar::keep_cue_memory_in_process();  // it receives the images as a module would
  try {
    std::filesystem::create_directories(out_dir);
    const auto file = (std::filesystem::path(out_dir) / "bench_replay.mcap").string();
    const auto schedule = write_file(file, duration_s, cameras);

    std::set<std::string> topics;
    for (const auto& [key, t] : schedule) topics.insert(key.first);
    std::mutex mutex;
    std::vector<std::tuple<std::string, std::uint64_t, std::uint64_t>> arrivals;
    arrivals.reserve(schedule.size());
    const auto arrived = [&](const std::string& topic, auto bytes, auto t) {
      const auto h = oscar::record::read_cue_header(bytes);
      std::lock_guard lock(mutex);
      arrivals.emplace_back(topic, h ? h->seq : 0, t);
    };
    // One participant per stream, as separate consumers of a real system have: each receives on
    // its own thread, so the measurement itself does not queue a Bool behind four images.
    std::vector<std::unique_ptr<oscar::DdsParticipant>> participants;
    std::map<std::string, std::unique_ptr<oscar::inspect::RawTap>> taps;
    for (const auto& t : topics) {
      participants.push_back(
          std::make_unique<oscar::DdsParticipant>(domain, "oscar-bench-replay " + t));
      taps[t] = std::make_unique<oscar::inspect::RawTap>(*participants.back(), arrived);
    }
    oscar::test::Process replay({(oscar::bench::own_dir() / "oscar-replay").string(), file,
                                 "--domain", std::to_string(domain)},
                                file + ".log");
    // Subscribe as the replayer's writers appear (it waits for readers before it starts).
    const auto until = std::chrono::steady_clock::now() + 10s;
    std::size_t subscribed = 0;
    while (subscribed < topics.size() && std::chrono::steady_clock::now() < until) {
      subscribed = 0;
      for (const auto& t : topics) subscribed += taps.at(t)->subscribe(t).empty() ? 0 : 1;
      std::this_thread::sleep_for(5ms);
    }
    if (subscribed < topics.size()) {
      fmt::print(stderr, "oscar bench replay: the replayer's topics did not appear:\n{}",
                 replay.output());
      return 1;
    }
    if (!replay.wait(std::chrono::seconds(static_cast<long>(duration_s) + 60))) {
      fmt::print(stderr, "oscar bench replay: the replay did not end:\n{}", replay.output());
      return 1;
    }
    std::this_thread::sleep_for(500ms);
    std::lock_guard lock(mutex);
    std::vector<double> offsets;
    std::vector<bool> is_image;
    for (const auto& [topic, seq, t] : arrivals) {
      const auto s = schedule.find({topic, seq});
      if (s == schedule.end()) continue;
      offsets.push_back(static_cast<double>(t) - static_cast<double>(s->second));
      is_image.push_back(topic.find("/cam") != std::string::npos);
    }
    const double shift = percentile(offsets, 0.5);
    std::vector<double> errors_us, image_us, bool_us;
    for (std::size_t i = 0; i < offsets.size(); ++i) {
      errors_us.push_back(std::abs(offsets[i] - shift) / 1e3);
      (is_image[i] ? image_us : bool_us).push_back(errors_us.back());
    }
    const double p50 = percentile(errors_us, 0.5), p99 = percentile(errors_us, 0.99);
    if (json) {
      fmt::print(
          "{}\n",
          nlohmann::ordered_json{{"timing_err_us_p50", p50}, {"timing_err_us_p99", p99}}.dump());
    } else {
      fmt::print(
          "oscar bench replay: {:.0f} s of {} x 30 Hz GvImage 768x576 + 1 kHz Bool\n"
          "received {} of {} replayed cues\ntiming error p50 {:.1f} us, p99 {:.1f} us, "
          "max {:.1f} us\n  Bool:    p50 {:.1f} us, p99 {:.1f} us\n"
          "  GvImage: p50 {:.1f} us, p99 {:.1f} us\nreplayer: {}",
          duration_s, cameras, offsets.size(), schedule.size(), p50, p99,
          percentile(errors_us, 1.0), percentile(bool_us, 0.5), percentile(bool_us, 0.99),
          percentile(image_us, 0.5), percentile(image_us, 0.99), replay.output());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench replay: %s\n", e.what());
    return 1;
  }
}
