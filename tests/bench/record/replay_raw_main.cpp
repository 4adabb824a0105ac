// oscar-bench-replay-raw: the floor for `oscar bench replay`. A plain Fast DDS publisher of the
// same schedule that reads no file: the typed cues are built beforehand, each topic has its own
// participant and thread (as oscar replay's lanes), the QoS of a module's output (reliable, keep
// last 16, volatile, synchronous) and OSCAR's loopback transport profile. Whatever timing error
// the bench measures for it is the machine's and Fast DDS's, not the replayer's.
//   oscar-bench-replay-raw SCHEDULE --domain D
// SCHEDULE has a line "topic type seq offset_ns" per cue (type oscar::GvImage or oscar::Bool);
// every GvImage cue is the bench's 768x576 frame.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <oscar/command_line.hpp>

#include "bench_common.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/output.hpp"
#include "oscar/process_util.hpp"
#include "oscar/topic_io.hpp"
#include "percentile.hpp"  // tests/common

namespace fdds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

namespace {

struct Lane {
  std::string topic;
  bool image = false;
  std::vector<std::pair<std::uint64_t, std::chrono::nanoseconds>> due;  ///< seq, offset
  std::unique_ptr<oscar::DdsParticipant> participant;
  fdds::DataWriter* writer = nullptr;
};

// How late each write began and how long it took (us).
struct Writes {
  std::vector<double> late_us, took_us;
};

// Publishes the lane's cues at their times.
template <class T>
Writes publish(const Lane& lane, T cue, Clock::time_point start) {
  oscar::wake_on_time();  // as oscar replay's lanes
  cue.header().source(lane.topic);
  const auto us = [](Clock::duration d) {
    return std::chrono::duration<double, std::micro>(d).count();
  };
  Writes w;
  w.late_us.reserve(lane.due.size());
  w.took_us.reserve(lane.due.size());
  for (const auto& [seq, offset] : lane.due) {
    std::this_thread::sleep_until(start + offset);
    const auto began = Clock::now();
    w.late_us.push_back(us(began - (start + offset)));
    cue.header().seq(seq);
    cue.header().stamps({oscar::bench::wall_ns()});
    lane.writer->write(&cue);
    w.took_us.push_back(us(Clock::now() - began));
  }
  return w;
}

using oscar::test::percentile;

std::map<std::string, Lane> read_schedule(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::map<std::string, Lane> lanes;
  std::string topic, type;
  std::uint64_t seq = 0, offset = 0;
  while (in >> topic >> type >> seq >> offset) {
    if (type != "oscar::GvImage" && type != "oscar::Bool") {
      throw std::runtime_error(path + ": type '" + type +
                               "' is neither oscar::GvImage nor oscar::Bool");
    }
    auto& lane = lanes[topic];
    lane.topic = topic;
    lane.image = type == "oscar::GvImage";
    lane.due.emplace_back(seq, std::chrono::nanoseconds(offset));
  }
  if (lanes.empty()) throw std::runtime_error(path + " holds no cues");
  return lanes;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "oscar-bench-replay-raw: plain Fast DDS publishing of oscar bench replay's schedule"};
  std::string schedule;
  int domain = 0;
  app.add_option("SCHEDULE", schedule, "a 'topic type seq offset_ns' line per cue")->required();
  app.add_option("--domain", domain);
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    auto lanes = read_schedule(schedule);
    std::size_t history_bytes = 0;
    for (auto& [topic, lane] : lanes) {
      lane.participant = std::make_unique<oscar::DdsParticipant>(domain, "oscar-bench-replay-raw");
      auto& t = lane.participant->topic(
          topic, lane.image ? oscar::cue_type_info<oscar::GvImage>().new_topic_type()
                            : oscar::cue_type_info<oscar::Bool>().new_topic_type());
      lane.writer = lane.participant->publisher().create_datawriter(
          &t, oscar::qos::cue_writer(oscar::OutputOptions{}));
      if (!lane.writer) throw std::runtime_error("cannot create a writer for " + topic);
      if (lane.image) history_bytes += (oscar::OutputOptions{}.depth + 1) * 768 * 576;
    }
    oscar::prefault_heap(history_bytes);  // as oscar replay does
    const auto until = Clock::now() + std::chrono::seconds(10);
    for (auto& [topic, lane] : lanes) {
      fdds::PublicationMatchedStatus matched;
      while (lane.writer->get_publication_matched_status(matched), matched.current_count == 0) {
        if (Clock::now() > until) throw std::runtime_error("no reader for " + topic);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    const auto start = Clock::now() + std::chrono::milliseconds(100);
    const auto image = oscar::bench::pal_image();
    std::vector<Writes> writes(lanes.size());
    std::vector<std::thread> threads;
    for (auto& [topic, lane] : lanes) {
      threads.emplace_back([&lane, &image, start, &w = writes[threads.size()]] {
        w = lane.image ? publish(lane, image, start) : publish(lane, oscar::Bool{}, start);
      });
    }
    for (auto& t : threads) t.join();
    std::vector<double> late, image_took;
    std::size_t i = 0;
    for (const auto& [topic, lane] : lanes) {
      const auto& w = writes[i++];
      late.insert(late.end(), w.late_us.begin(), w.late_us.end());
      if (lane.image) image_took.insert(image_took.end(), w.took_us.begin(), w.took_us.end());
    }
    // The line oscar replay prints too.
    std::printf("publishing began late by p50 %.0f us, p99 %.0f us, max %.0f us\n",
                percentile(late, 0.5), percentile(late, 0.99), percentile(late, 1.0));
    if (!image_took.empty()) {
      std::printf("an image's write took p50 %.0f us, p90 %.0f us, p99 %.0f us\n",
                  percentile(image_took, 0.5), percentile(image_took, 0.9),
                  percentile(image_took, 0.99));
    }
    for (auto& [topic, lane] : lanes) {
      lane.writer->wait_for_acknowledgments({2, 0});
      lane.participant->publisher().delete_datawriter(lane.writer);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-bench-replay-raw: %s\n", e.what());
    return 1;
  }
}
