// oscar bench record: four 30 Hz 768x576 GvImage streams and one 1 kHz Bool stream, published
// from this process on loopback, recorded by an oscar-record child for --duration seconds;
// published, written (messages in the MCAP file), dropped, MB/s written and the recorder's CPU.
#include <csignal>
#include <cstdio>
#include <memory>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>

#include "bench_common.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/mcap/reader.hpp"
#include "oscar/topic_io.hpp"
#include "process.hpp"  // tests/common

namespace {
namespace dds = eprosima::fastdds::dds;
using namespace std::chrono_literals;

dds::DataWriterQos cue_writer_qos() {
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 64;
  return q;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench record: recorder throughput with 4 x 30 Hz images + 1 kHz Bool"};
  bool json = false;
  std::string out_dir = "/tmp/oscar-bench-record";
  double duration_s = 60;
  int domain = 230;
  std::string compression = "none";
  app.add_flag("--json", json, "print {published, written, dropped, mb_s, cpu_pct}");
  app.add_option("--out-dir", out_dir, "where the MCAP file is written (and kept)");
  app.add_option("--duration", duration_s, "seconds of publishing")->check(CLI::PositiveNumber);
  app.add_option("--compression", compression, "the recorder's compression (zstd, lz4, none)");
  app.add_option("-d,--domain", domain, "DDS domain");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    std::filesystem::create_directories(out_dir);
    const auto file = (std::filesystem::path(out_dir) / "bench_record.mcap").string();
    oscar::DdsParticipant participant(domain, "oscar-bench-record");
    using BoolWriter = oscar::TopicWriter<oscar::Bool, oscar::BoolPubSubType>;
    using ImageWriter = oscar::TopicWriter<oscar::GvImage, oscar::GvImagePubSubType>;
    const auto streams = oscar::bench::streams();
    std::vector<std::unique_ptr<ImageWriter>> images;
    std::unique_ptr<BoolWriter> flag;
    for (const auto& s : streams) {
      const auto topic = "oscar/cue/" + s.kernel + "/out";
      if (s.image) {
        images.push_back(std::make_unique<ImageWriter>(participant, topic, cue_writer_qos()));
      } else {
        flag = std::make_unique<BoolWriter>(participant, topic, cue_writer_qos());
      }
    }
    oscar::test::Process recorder(
        {(oscar::bench::own_dir() / "oscar-record").string(), "--all", "-o", file, "--domain",
         std::to_string(domain), "--compression", compression},
        file + ".log");
    const auto until = std::chrono::steady_clock::now() + 20s;
    const auto matched = [&] {
      for (auto& w : images) {
        if (w->matched() == 0) return false;
      }
      return flag->matched() > 0;
    };
    while (!matched()) {
      if (std::chrono::steady_clock::now() > until) {
        fmt::print(stderr, "oscar bench record: the recorder did not subscribe within 20 s:\n{}",
                   recorder.output());
        return 1;
      }
      std::this_thread::sleep_for(50ms);
    }
    std::this_thread::sleep_for(500ms);

    auto image = oscar::bench::pal_image();
    oscar::Bool b;
    std::vector<std::uint64_t> seq(streams.size(), 0);
    std::uint64_t published = 0;
    const double cpu0 = oscar::bench::cpu_seconds(recorder.pid());
    const auto start = std::chrono::steady_clock::now();
    const auto end = start + std::chrono::nanoseconds(static_cast<long>(duration_s * 1e9));
    std::vector<std::chrono::steady_clock::time_point> next(streams.size(), start);
    while (true) {
      // The stream due first; sleep until then.
      std::size_t i = 0;
      for (std::size_t k = 1; k < streams.size(); ++k) {
        if (next[k] < next[i]) i = k;
      }
      if (next[i] >= end) break;
      std::this_thread::sleep_until(next[i]);
      next[i] += streams[i].period;
      auto& header = streams[i].image ? image.header() : b.header();
      header.seq(++seq[i]);
      header.source(streams[i].kernel + "/out");
      header.stamps({oscar::bench::wall_ns()});
      if (streams[i].image) {
        images[i]->write(image);
      } else {
        b.value(seq[i] % 2 == 1);
        flag->write(b);
      }
      ++published;
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::this_thread::sleep_for(1s);  // the last samples arrive
    const double cpu = oscar::bench::cpu_seconds(recorder.pid()) - cpu0;
    kill(recorder.pid(), SIGINT);
    if (!recorder.wait(60s)) {
      fmt::print(stderr, "oscar bench record: the recorder did not finish:\n{}", recorder.output());
      return 1;
    }
    oscar::mcap::Reader reader(file);
    const auto info = reader.info();
    std::uint64_t written = info.statistics.message_count, payload = 0;
    reader.read_messages([&](const oscar::mcap::Channel&, const oscar::mcap::MessageView& m) {
      payload += m.data.size();
    });
    const double mb_s = static_cast<double>(payload) / 1e6 / wall;
    const double cpu_pct = 100.0 * cpu / wall;
    const auto dropped = published > written ? published - written : 0;
    if (json) {
      fmt::print("{}\n", nlohmann::ordered_json{{"published", published},
                                                {"written", written},
                                                {"dropped", dropped},
                                                {"mb_s", mb_s},
                                                {"cpu_pct", cpu_pct}}
                             .dump());
    } else {
      fmt::print(
          "oscar bench record: {:.1f} s, 4 x 30 Hz GvImage 768x576 + 1 kHz Bool, compression {}\n"
          "published {}, written {}, dropped {}\n{:.1f} MB/s payload written, recorder CPU {:.1f} %"
          " (of one core)\nfile {} ({:.1f} MB)\nrecorder: {}",
          wall, compression, published, written, dropped, mb_s, cpu_pct, file,
          static_cast<double>(info.file_size) / 1e6, recorder.output());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench record: %s\n", e.what());
    return 1;
  }
}
