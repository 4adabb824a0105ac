// oscar-bench-raw: the raw Fast DDS baseline for `oscar bench cueflow`. The same types and QoS
// (reliable, keep last 16, volatile) as the framework, but no frame: one writer, one reader that
// takes each sample and notes its arrival time. The configuration is chosen on the command line,
// so the bench can find the fastest per row (docs/benchmarks.md):
//   --delivery waitset|listener   a thread waiting on the reader's status condition, or a listener
//   --publish  sync|async         the writer's publish mode
//   --transport shm|udp           OSCAR's loopback profile (UDP on 127.0.0.1 plus shared memory),
//                                 or UDP on 127.0.0.1 alone
//   oscar-bench-raw pub  --type T --count N --period-us P --domain D [config]
//   oscar-bench-raw sub  --type T --expect N --warmup W --report FILE --domain D [config]
//   oscar-bench-raw both --type T --count N --period-us P --expect N --warmup W --report FILE
// --network '{interfaces: [...], peers: [...], shared_memory: false}' gives another transport
// profile (a `network:` map of docs/network.md), as OSCAR's modules of the remote constellation;
// --transport udp then also turns shared memory off.
#include <chrono>
#include <cstdio>
#include <thread>

#include <yaml-cpp/yaml.h>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <oscar/command_line.hpp>

#include <oscar/cue_type_info.hpp>
#include <oscar/cue_types.hpp>
#include <oscar/dds_participant.hpp>
#include <oscar/time.hpp>

#include "peers/fastdds_cue_qos.hpp"
#include "peers/peer_common.hpp"

namespace fdds = eprosima::fastdds::dds;
using oscar::bench::LatencyLog;
using oscar::bench::PeerOptions;

namespace {

struct Config {
  std::string delivery = "listener", publish = "sync", transport = "shm";
  std::string network;  ///< a `network:` map; empty: the loopback profile
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

fdds::DataWriterQos writer_qos(const Config& c) {
  auto q = oscar::bench::with_cue_qos(fdds::DATAWRITER_QOS_DEFAULT);
  q.publish_mode().kind =
      c.publish == "async" ? fdds::ASYNCHRONOUS_PUBLISH_MODE : fdds::SYNCHRONOUS_PUBLISH_MODE;
  return q;
}

// Takes every sample the reader holds into one reused cue and logs its latency.
template <class T>
class Taker final : public fdds::DataReaderListener {
 public:
  explicit Taker(LatencyLog& log) : log_(log) {}
  void on_data_available(fdds::DataReader* reader) override { take_all(*reader); }
  void take_all(fdds::DataReader& reader) {
    fdds::SampleInfo info;
    while (reader.take_next_sample(&cue_, &info) == ReturnCode_t::RETCODE_OK) {
      const auto now = oscar::wall_now();
      if (info.valid_data) {
        log_.add(now - oscar::generation_stamp(cue_.header()), cue_.header().seq());
      }
    }
  }

 private:
  LatencyLog& log_;
  T cue_ = prototype<T>();
};

// The wait-set delivery: this thread blocks on the reader's data-available status.
void wait_and_take(fdds::DataReader& reader, auto& taker, const LatencyLog& log) {
  fdds::WaitSet waitset;
  auto& condition = reader.get_statuscondition();
  condition.set_enabled_statuses(fdds::StatusMask::data_available());
  waitset.attach_condition(condition);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!log.done() && std::chrono::steady_clock::now() < until) {
    fdds::ConditionSeq active;
    if (waitset.wait(active, eprosima::fastrtps::Duration_t(0, 100'000'000)) !=
        ReturnCode_t::RETCODE_OK) {
      continue;
    }
    reader.get_status_changes();
    taker.take_all(reader);
  }
}

template <class T>
int run(const PeerOptions& o, const Config& c) {
  auto network = oscar::NetworkConfig::from_yaml(YAML::Load(c.network));
  if (c.transport == "udp") network.shared_memory = false;
  oscar::DdsParticipant participant(o.domain, "oscar-bench-raw:" + o.mode, network);
  auto& topic =
      participant.topic("oscar/bench/raw/" + o.type, oscar::cue_type_info<T>().new_topic_type());
  LatencyLog log(o);
  Taker<T> taker(log);
  fdds::DataReader* reader = nullptr;
  std::thread waiter;
  if (o.mode != "pub") {
    const bool listener = c.delivery == "listener";
    reader = participant.subscriber().create_datareader(
        &topic, oscar::bench::with_cue_qos(fdds::DATAREADER_QOS_DEFAULT),
        listener ? &taker : nullptr,
        listener ? fdds::StatusMask::data_available() : fdds::StatusMask::none());
    if (!listener) waiter = std::thread([&] { wait_and_take(*reader, taker, log); });
  }
  fdds::DataWriter* writer = nullptr;
  if (o.mode != "sub") {
    writer = participant.publisher().create_datawriter(&topic, writer_qos(c));
    fdds::PublicationMatchedStatus matched;
    while (writer->get_publication_matched_status(matched), matched.current_count == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // let both sides settle
    auto cue = prototype<T>();
    oscar::bench::Pacer pacer(o.period_us);
    for (int i = 1; i <= o.count && !(reader && log.done()) && !oscar::bench::stop_requested();
         ++i) {
      cue.header().seq(static_cast<unsigned long long>(i));
      cue.header().stamps().assign(1, static_cast<unsigned long long>(oscar::wall_now()));
      writer->write(&cue);
      pacer.wait();
    }
  }
  if (reader) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!log.done() && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (waiter.joinable()) waiter.join();
    log.write_report();
    participant.subscriber().delete_datareader(reader);
  }
  if (writer) participant.publisher().delete_datawriter(writer);
  return reader && !log.done() ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar-bench-raw: raw Fast DDS latency baseline"};
  PeerOptions o;
  Config c;
  oscar::bench::add_peer_options(app, o);
  app.add_option("--delivery", c.delivery)->check(CLI::IsMember({"waitset", "listener"}));
  app.add_option("--publish", c.publish)->check(CLI::IsMember({"sync", "async"}));
  app.add_option("--transport", c.transport)->check(CLI::IsMember({"shm", "udp"}));
  app.add_option("--network", c.network, "transport profile, a YAML `network:` map");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  oscar::bench::install_stop_handler();
  try {
    oscar::register_standard_cue_types();
    return oscar::visit_standard_type(o.type, [&]<class T>() { return run<T>(o, c); });
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-bench-raw: %s\n", e.what());
    return 2;
  }
}
