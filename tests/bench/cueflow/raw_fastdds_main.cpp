// oscar-bench-raw: the raw Fast DDS baseline for `oscar bench cueflow`. The same types, QoS
// (reliable, keep last 16, volatile, synchronous) and transport (OSCAR's loopback participant
// profile: UDP on 127.0.0.1 plus shared memory) as the framework, but no frame: one writer, one
// reader with a listener that takes each sample and notes its arrival time.
//   oscar-bench-raw pub  --type T --count N --period-us P --domain D
//   oscar-bench-raw sub  --type T --expect N --warmup W --report FILE --domain D
//   oscar-bench-raw both --type T --count N --period-us P --expect N --warmup W --report FILE
// --network '{interfaces: [...], peers: [...], shared_memory: false}' gives another transport
// profile (a `network:` map of docs/network.md), as OSCAR's modules of the remote constellation.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <CLI/CLI.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <oscar/command_line.hpp>

#include <oscar/cue_type_info.hpp>
#include <oscar/cue_types.hpp>
#include <oscar/dds_participant.hpp>
#include <oscar/time.hpp>

namespace fdds = eprosima::fastdds::dds;

namespace {

struct Options {
  std::string type = "Bool", report, network;
  int count = 1000, expect = 1000, warmup = 50, period_us = 2000, domain = 0;
};

template <class T>
T prototype() {
  T cue{};
  if constexpr (std::is_same_v<T, oscar::LineSeg3DSeq>) {
    cue.lines().resize(100);
  } else if constexpr (std::is_same_v<T, oscar::GvImage>) {
    cue.dx(768);
    cue.dy(576);
    cue.image().assign(768u * 576u, 0x80);
  }
  return cue;
}

fdds::DataWriterQos writer_qos() {
  fdds::DataWriterQos q = fdds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 16;
  q.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  q.publish_mode().kind = fdds::SYNCHRONOUS_PUBLISH_MODE;
  return q;
}

fdds::DataReaderQos reader_qos() {
  fdds::DataReaderQos q = fdds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 16;  // as bench_sink's input
  q.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  return q;
}

template <class T>
class Sub final : public fdds::DataReaderListener {
 public:
  explicit Sub(const Options& o) : o_(o) {}
  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    for (;;) {
      auto cue = std::make_shared<T>();
      if (reader->take_next_sample(cue.get(), &info) != ReturnCode_t::RETCODE_OK) break;
      const auto now = oscar::wall_now();
      if (!info.valid_data) continue;
      std::lock_guard lock(mutex_);
      ++received_;
      if (received_ > static_cast<std::uint64_t>(o_.warmup)) {
        latency_ns_.push_back(now - oscar::generation_stamp(cue->header()));
      }
      if (received_ == static_cast<std::uint64_t>(o_.expect)) done_ = true;
    }
  }
  bool done() {
    std::lock_guard lock(mutex_);
    return done_;
  }
  void write_report() {
    std::lock_guard lock(mutex_);
    auto v = latency_ns_;
    std::sort(v.begin(), v.end());
    const auto at = [&](double q) {
      return v.empty() ? 0.0
                       : v[std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()))] / 1e3;
    };
    std::ofstream(o_.report)
        << fmt::format(
               R"({{"type":"{}","received":{},"samples":{},"delivery_us":{{"p50":{:.2f},"p90":{:.2f},"max":{:.2f}}}}})",
               o_.type, received_, v.size(), at(0.5), at(0.9), v.empty() ? 0.0 : v.back() / 1e3)
        << "\n";
  }

 private:
  const Options& o_;
  std::mutex mutex_;
  std::uint64_t received_ = 0;
  std::vector<std::int64_t> latency_ns_;
  bool done_ = false;
};

template <class T>
int run(const std::string& mode, const Options& o) {
  oscar::DdsParticipant participant(o.domain, "oscar-bench-raw:" + mode,
                                    oscar::NetworkConfig::from_yaml(YAML::Load(o.network)));
  auto& topic =
      participant.topic("oscar/bench/raw/" + o.type, oscar::cue_type_info<T>().new_topic_type());
  std::unique_ptr<Sub<T>> sub;
  fdds::DataReader* reader = nullptr;
  if (mode != "pub") {
    sub = std::make_unique<Sub<T>>(o);
    reader = participant.subscriber().create_datareader(&topic, reader_qos(), sub.get());
  }
  fdds::DataWriter* writer = nullptr;
  if (mode != "sub") {
    writer = participant.publisher().create_datawriter(&topic, writer_qos());
    fdds::PublicationMatchedStatus matched;
    while (writer->get_publication_matched_status(matched), matched.current_count == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // let both sides settle
    auto cue = prototype<T>();
    auto next = std::chrono::steady_clock::now();
    for (int i = 1; i <= o.count; ++i) {
      cue.header().seq(static_cast<unsigned long long>(i));
      cue.header().stamps().assign(1, static_cast<unsigned long long>(oscar::wall_now()));
      writer->write(&cue);
      next += std::chrono::microseconds(o.period_us);
      std::this_thread::sleep_until(next);
      if (sub && sub->done()) break;
    }
  }
  if (sub) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!sub->done() && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    sub->write_report();
  }
  if (reader) participant.subscriber().delete_datareader(reader);
  if (writer) participant.publisher().delete_datawriter(writer);
  return sub && !sub->done() ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar-bench-raw: raw Fast DDS latency baseline"};
  std::string mode;
  Options o;
  app.add_option("mode", mode, "pub, sub or both")
      ->required()
      ->check(CLI::IsMember({"pub", "sub", "both"}));
  app.add_option("--type", o.type)->check(CLI::IsMember({"Bool", "LineSeg3DSeq", "GvImage"}));
  app.add_option("--count", o.count);
  app.add_option("--expect", o.expect);
  app.add_option("--warmup", o.warmup);
  app.add_option("--period-us", o.period_us);
  app.add_option("--report", o.report);
  app.add_option("--domain", o.domain);
  app.add_option("--network", o.network, "transport profile, a YAML `network:` map");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    oscar::register_standard_cue_types();
    return oscar::visit_standard_type(o.type, [&]<class T>() { return run<T>(mode, o); });
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-bench-raw: %s\n", e.what());
    return 2;
  }
}
