// oscar bench replay: writes an MCAP file with the five streams of issue 4 on an exact schedule
// (four 30 Hz GvImage, one 1 kHz Bool), replays it with an oscar-replay child and measures, for
// every cue received here, how far its arrival is from the original schedule: the error of
// (arrival - log time) against its median over all cues (the replay's start is a free shift).
// In the same run, alternating, oscar-bench-replay-raw publishes the same schedule with plain
// Fast DDS and no file: the floor this machine sets.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <regex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>

#include "bench_common.hpp"
#include "oscar/cue_header_cdr.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/mcap/reader.hpp"
#include "oscar/mcap/writer.hpp"
#include "oscar/process_util.hpp"
#include "percentile.hpp"  // tests/common
#include "process.hpp"     // tests/common
#include "raw_tap.hpp"     // tools/inspect

namespace {
using namespace std::chrono_literals;

// The cues a publisher has to deliver, each due at its log time.
struct Schedule {
  struct Cue {
    std::string topic, type;
    std::uint64_t seq, log_time;
  };
  std::vector<Cue> cues;                                                    ///< in time order
  std::map<std::pair<std::string, std::uint64_t>, std::uint64_t> log_time;  ///< (topic, seq)
  std::set<std::string> image_topics;

  void add(Cue c) {
    log_time[{c.topic, c.seq}] = c.log_time;
    if (c.type == "oscar::GvImage") image_topics.insert(c.topic);
    cues.push_back(std::move(c));
  }
  // For oscar-bench-replay-raw: "topic type seq offset_ns" lines, the offset from the first cue.
  void write_text(const std::string& path) const {
    std::ofstream out(path);
    for (const auto& c : cues) {
      out << c.topic << ' ' << c.type << ' ' << c.seq << ' ' << c.log_time - cues.front().log_time
          << '\n';
    }
    if (!out) throw std::runtime_error("cannot write " + path);
  }
};

// Writes the five streams on an exact schedule (every stream starts at the same instant) into
// an MCAP file and returns the schedule.
Schedule write_file(const std::string& path, double seconds, int cameras) {
  oscar::mcap::WriterOptions o;
  o.compression = oscar::mcap::Compression::kNone;
  oscar::mcap::Writer w(path, o);
  const auto schema_of = [&](const std::string& type) {
    const auto& idl = oscar::idl_texts().at(type);
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
  std::stable_sort(due.begin(), due.end(), [](const Due& a, const Due& b) { return a.t < b.t; });
  auto image = oscar::bench::pal_image();
  oscar::Bool b;
  Schedule schedule;
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
    schedule.add(
        {"oscar/cue/" + s.kernel + "/out", s.image ? "oscar::GvImage" : "oscar::Bool", d.seq, d.t});
  }
  w.close();
  return schedule;
}

// The schedule a recording holds (e.g. one `oscar bench record --out-dir` kept): its GvImage and
// Bool cues at their log times.
Schedule schedule_of(const std::string& path) {
  oscar::mcap::Reader reader(path);
  const auto info = reader.info();
  Schedule schedule;
  reader.read_messages([&](const oscar::mcap::Channel& ch, const oscar::mcap::MessageView& m) {
    const auto s = info.schemas.find(ch.schema_id);
    const std::string type = s == info.schemas.end() ? "" : s->second.name;
    if (type != "oscar::GvImage" && type != "oscar::Bool") {
      throw std::invalid_argument(fmt::format(
          "{}: topic '{}' has type '{}'; the bench replays GvImage and Bool topics only", path,
          ch.topic, type));
    }
    const auto header = oscar::read_cue_header(m.data);
    if (!header) {
      throw std::invalid_argument(
          fmt::format("{}: a message on '{}' has no readable cue header", path, ch.topic));
    }
    schedule.add({ch.topic, type, header->seq(), m.log_time});
  });
  if (schedule.cues.empty()) throw std::invalid_argument(path + ": the recording holds no cues");
  return schedule;
}

using oscar::test::percentile;

// One publisher's run as the consumers saw it: each cue's error against the schedule (us).
struct Run {
  std::vector<double> all, bools, images;
  std::string output;                 ///< the publisher's own report
  double late_p50 = 0, late_p99 = 0;  ///< how late its writes began, by its own clock (us)
  double p50() const { return percentile(all, 0.5); }
  double p99() const { return percentile(all, 0.99); }
};

// Starts `publisher`, receives every topic of the schedule on a participant of its own (as
// separate consumers of a real system do: a Bool is never queued behind four images here), and
// measures each cue's (arrival - log time) against the median of all (the start is a free shift).
Run measure(const std::vector<std::string>& publisher, const Schedule& schedule, int domain,
            double seconds, const std::string& log) {
  std::set<std::string> topics;
  for (const auto& c : schedule.cues) topics.insert(c.topic);
  std::mutex mutex;
  std::vector<std::tuple<std::string, std::uint64_t, std::uint64_t>> arrivals;
  arrivals.reserve(schedule.cues.size());
  const auto arrived = [&](const std::string& topic, auto bytes, auto t) {
    const auto h = oscar::read_cue_header(bytes);
    std::lock_guard lock(mutex);
    arrivals.emplace_back(topic, h ? h->seq() : 0, t);
  };
  std::vector<std::unique_ptr<oscar::DdsParticipant>> participants;
  std::map<std::string, std::unique_ptr<oscar::inspect::RawTap>> taps;
  for (const auto& t : topics) {
    participants.push_back(
        std::make_unique<oscar::DdsParticipant>(domain, "oscar-bench-replay " + t));
    taps[t] = std::make_unique<oscar::inspect::RawTap>(*participants.back(), arrived);
  }
  oscar::test::Process child(publisher, log);
  // Subscribe as the publisher's writers appear (it waits for readers before it starts).
  const auto until = std::chrono::steady_clock::now() + 10s;
  std::size_t subscribed = 0;
  while (subscribed < topics.size() && std::chrono::steady_clock::now() < until) {
    subscribed = 0;
    for (const auto& t : topics) subscribed += taps.at(t)->subscribe(t).empty() ? 0 : 1;
    std::this_thread::sleep_for(5ms);
  }
  if (subscribed < topics.size()) {
    throw std::runtime_error(publisher[0] + "'s topics did not appear:\n" + child.output());
  }
  const auto status = child.wait(std::chrono::seconds(static_cast<long>(seconds) + 60));
  if (status != 0) throw std::runtime_error(publisher[0] + " failed:\n" + child.output());
  std::this_thread::sleep_for(500ms);
  std::lock_guard lock(mutex);
  std::vector<double> offsets;
  std::vector<bool> is_image;
  for (const auto& [topic, seq, t] : arrivals) {
    const auto s = schedule.log_time.find({topic, seq});
    if (s == schedule.log_time.end()) continue;
    offsets.push_back(static_cast<double>(t) - static_cast<double>(s->second));
    is_image.push_back(schedule.image_topics.count(topic) > 0);
  }
  const double shift = percentile(offsets, 0.5);
  Run run;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    run.all.push_back(std::abs(offsets[i] - shift) / 1e3);
    (is_image[i] ? run.images : run.bools).push_back(run.all.back());
  }
  run.output = child.output();
  static const std::regex late(R"(publishing began late by p50 ([0-9.]+) us, p99 ([0-9.]+) us)");
  std::smatch m;
  if (!std::regex_search(run.output, m, late)) {
    throw std::runtime_error(publisher[0] + " did not say how late it published:\n" + run.output);
  }
  run.late_p50 = std::stod(m[1]);
  run.late_p99 = std::stod(m[2]);
  return run;
}

double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench replay: timing error of replayed cues against the original schedule"};
  bool json = false;
  std::string out_dir = "/tmp/oscar-bench-replay";
  double duration_s = 10;
  int domain = 229;
  int cameras = 4;
  int repeat = 3;
  std::string recording;
  app.add_flag("--json", json,
               "print {timing_err_us_p50, timing_err_us_p99, raw_timing_err_us_p50, "
               "raw_timing_err_us_p99, p99_ratio} (medians of the runs)");
  app.add_option("--out-dir", out_dir, "where the MCAP file is written (and kept)");
  app.add_option("--duration", duration_s, "seconds of recording to replay")
      ->check(CLI::PositiveNumber);
  app.add_option("--cameras", cameras, "30 Hz GvImage streams beside the 1 kHz Bool (0..4)")
      ->check(CLI::Range(0, 4));
  app.add_option("--repeat", repeat, "runs of each publisher, alternating (medians are reported)")
      ->check(CLI::PositiveNumber);
  app.add_option("--file", recording,
                 "replay this recording (e.g. one `oscar bench record --out-dir` kept) instead of "
                 "writing one: its log times are the schedule")
      ->check(CLI::ExistingFile);
  app.add_option("-d,--domain", domain, "DDS domain");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  oscar::keep_cue_memory_in_process();  // it receives the images as a module would
  try {
    std::filesystem::create_directories(out_dir);
    const auto written = (std::filesystem::path(out_dir) / "bench_replay.mcap").string();
    const auto file = recording.empty() ? written : recording;
    const auto schedule =
        recording.empty() ? write_file(file, duration_s, cameras) : schedule_of(recording);
    const auto seconds =
        static_cast<double>(schedule.cues.back().log_time - schedule.cues.front().log_time) / 1e9;
    const auto schedule_text = written + ".schedule";
    schedule.write_text(schedule_text);
    const auto dir = oscar::bench::own_dir();
    const std::vector<std::string> replay{(dir / "oscar-replay").string(), file, "--domain",
                                          std::to_string(domain)};
    const std::vector<std::string> raw{(dir / "oscar-bench-replay-raw").string(), schedule_text,
                                       "--domain", std::to_string(domain)};
    std::vector<Run> replays, raws;
    if (!json) {
      const auto what =
          recording.empty()
              ? fmt::format(
                    "{:g} s of {} x 30 Hz GvImage 768x576 + 1 kHz Bool, all streams in "
                    "phase",
                    duration_s, cameras)
              : fmt::format("{}: {} cues in {:.1f} s", recording, schedule.cues.size(), seconds);
      fmt::print(
          "oscar bench replay: {}; {} run(s) of each publisher, alternating\n"
          "timing error against the schedule, us: at arrival in a consumer (each cue's arrival "
          "against the median of all),\nand when the write began (the publisher's own clock)\n"
          "{:<4} {:<13} {:>13} | {:>8} {:>8} {:>9} {:>9} {:>9} {:>9} | {:>9} {:>9}\n",
          what, repeat, "run", "publisher", "received", "p50", "p99", "max", "Bool p99",
          "image p50", "image p99", "write p50", "write p99");
    }
    const auto row = [&](int r, const char* who, const Run& run) {
      if (json) return;
      fmt::print(
          "{:<4} {:<13} {:>6}/{:<6} | {:>8.1f} {:>8.1f} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} | "
          "{:>9.0f} {:>9.0f}\n",
          r, who, run.all.size(), schedule.cues.size(), run.p50(), run.p99(),
          percentile(run.all, 1.0), percentile(run.bools, 0.99), percentile(run.images, 0.5),
          percentile(run.images, 0.99), run.late_p50, run.late_p99);
      std::fflush(stdout);
    };
    for (int r = 1; r <= repeat; ++r) {
      raws.push_back(measure(raw, schedule, domain, seconds, written + ".raw.log"));
      row(r, "raw Fast DDS", raws.back());
      replays.push_back(measure(replay, schedule, domain, seconds, written + ".log"));
      row(r, "oscar replay", replays.back());
    }
    struct Medians {
      double p50, p99, late_p50, late_p99;
    };
    const auto medians = [](const std::vector<Run>& runs) {
      std::vector<double> p50, p99, late_p50, late_p99;
      for (const auto& run : runs) {
        p50.push_back(run.p50());
        p99.push_back(run.p99());
        late_p50.push_back(run.late_p50);
        late_p99.push_back(run.late_p99);
      }
      return Medians{median(p50), median(p99), median(late_p50), median(late_p99)};
    };
    const auto ours = medians(replays);
    const auto floor = medians(raws);
    if (json) {
      // Plain Fast DDS publishing the same schedule in the same runs: the replay's figure as a
      // ratio.
      fmt::print("{}\n",
                 nlohmann::ordered_json{{"timing_err_us_p50", ours.p50},
                                        {"timing_err_us_p99", ours.p99},
                                        {"raw_timing_err_us_p50", floor.p50},
                                        {"raw_timing_err_us_p99", floor.p99},
                                        {"p99_ratio", floor.p99 > 0 ? ours.p99 / floor.p99 : 0.0}}
                     .dump());
    } else {
      fmt::print(
          "medians of the runs:\n"
          "  at arrival:   oscar replay p50 {:.1f} us, p99 {:.1f} us; raw Fast DDS p50 {:.1f} us, "
          "p99 {:.1f} us; p99 ratio {:.2f}\n"
          "  write began:  oscar replay p50 {:.0f} us, p99 {:.0f} us; raw Fast DDS p50 {:.0f} us, "
          "p99 {:.0f} us\n"
          "raw Fast DDS's last run:\n{}oscar replay's last run:\n{}",
          ours.p50, ours.p99, floor.p50, floor.p99, floor.p99 > 0 ? ours.p99 / floor.p99 : 0.0,
          ours.late_p50, ours.late_p99, floor.late_p50, floor.late_p99, raws.back().output,
          replays.back().output);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench replay: %s\n", e.what());
    return 1;
  }
}
