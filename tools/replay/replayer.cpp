#include "replayer.hpp"

#include <fnmatch.h>

#include <cstdio>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/mcap/reader.hpp"
#include "raw_cdr_type.hpp"
#include "recorder.hpp"  // topic_of

namespace oscar::replay {
namespace dds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

namespace {
struct Stopped {};  // ends a scan early
}  // namespace

struct Replayer::Impl {
  ReplayOptions o;
  mcap::Reader reader;
  mcap::FileInfo info;
  std::optional<DdsParticipant> participant;
  std::map<std::uint16_t, dds::DataWriter*> writers;  // channel id -> writer (selected only)

  explicit Impl(ReplayOptions options)
      : o(std::move(options)), reader(o.file), info(reader.info()) {
    if (!(o.rate > 0)) throw std::invalid_argument("--rate must be > 0");
    std::map<std::uint16_t, std::pair<std::string, std::string>> selected;  // topic, type
    for (const auto& [id, c] : info.channels) {
      if (!wanted(c.topic)) continue;
      std::string type;
      if (auto s = info.schemas.find(c.schema_id); s != info.schemas.end()) type = s->second.name;
      if (type.empty() && c.metadata.count("type")) type = c.metadata.at("type");
      if (type.empty()) {
        throw std::invalid_argument(
            fmt::format("{}: channel '{}' names no type (no schema, no "
                        "'type' metadata): it cannot be published",
                        o.file, c.topic));
      }
      const auto to = o.remap.find(c.topic);
      selected[id] = {to == o.remap.end() ? c.topic : to->second, type};
    }
    for (const auto& [from, to] : o.remap) {
      bool found = false;
      for (const auto& [id, c] : info.channels) found = found || c.topic == from;
      if (!found) {
        throw std::invalid_argument(
            fmt::format("--remap {}:={}: the recording has no topic '{}'", from, to, from));
      }
    }
    if (selected.empty()) {
      throw std::invalid_argument(
          fmt::format("{}: no recorded topic matches the selection", o.file));
    }
    participant.emplace(o.domain, "oscar-replay");
    // Let discovery see the running system first: a topic there of another type is an error.
    std::this_thread::sleep_for(std::chrono::milliseconds(1200));
    for (const auto& [id, tt] : selected) {
      auto& topic = participant->topic(tt.first, new record::RawCdrType(tt.second));
      dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
      q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
      q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
      q.history().depth = 64;
      q.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
      auto* w = participant->publisher().create_datawriter(&topic, q);
      if (!w) throw std::runtime_error("cannot create a writer for " + tt.first);
      writers[id] = w;
      fmt::print(stderr, "replaying {} as {} ({})\n", info.channels.at(id).topic, tt.first,
                 tt.second);
    }
  }

  ~Impl() {
    if (participant) {
      for (auto& [id, w] : writers) participant->publisher().delete_datawriter(w);
    }
  }

  bool wanted(const std::string& topic) const {
    if (o.topics.empty()) return true;
    for (const auto& t : o.topics) {
      if (fnmatch(record::topic_of(t).c_str(), topic.c_str(), 0) == 0) return true;
    }
    return false;
  }

  void wait_for_readers() {
    const auto until = Clock::now() + o.wait_for_readers;
    for (auto& [id, w] : writers) {
      dds::PublicationMatchedStatus status;
      while (Clock::now() < until) {
        w->get_publication_matched_status(status);
        if (status.current_count > 0) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
  }
};

Replayer::Replayer(ReplayOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
Replayer::~Replayer() = default;

ReplayCounters Replayer::run(const std::atomic<bool>& stop) {
  auto& d = *impl_;
  d.wait_for_readers();
  ReplayCounters c;
  c.topics = d.writers.size();
  const auto begun = Clock::now();
  const std::uint64_t first = d.info.statistics.message_start_time;
  const std::uint64_t from = first + (d.o.start ? d.o.start->count() : 0);
  const std::uint64_t to = d.o.end ? first + d.o.end->count() : UINT64_MAX;
  record::RawSample sample;
  try {
    do {
      const auto pass_start = Clock::now();
      d.reader.read_messages([&](const mcap::Channel& ch, const mcap::MessageView& m) {
        if (stop) throw Stopped{};
        const auto w = d.writers.find(ch.id);
        if (w == d.writers.end() || m.log_time < from || m.log_time > to) return;
        if (d.o.step) {
          fmt::print(stderr, "[{}] {} seq {} at +{:.3f} s; Enter publishes it", c.published + 1,
                     ch.topic, m.sequence, (m.log_time - first) / 1e9);
          std::string line;
          if (!std::getline(std::cin, line)) throw Stopped{};
        } else {
          const auto due =
              pass_start +
              std::chrono::nanoseconds(static_cast<std::int64_t>((m.log_time - from) / d.o.rate));
          std::this_thread::sleep_until(due);
        }
        sample.bytes.assign(m.data.begin(), m.data.end());
        w->second->write(&sample);
        ++c.published;
        if (d.o.progress && c.published % 50 == 0) {
          std::fprintf(stderr, "\r\033[K%llu published  +%.1f s",
                       static_cast<unsigned long long>(c.published), (m.log_time - first) / 1e9);
        }
      });
    } while (d.o.loop && !stop);
  } catch (const Stopped&) {
  }
  if (d.o.progress) std::fputs("\n", stderr);
  // Reliable writers: give late acknowledgements a moment before the participant goes.
  for (auto& [id, w] : d.writers) w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
  c.seconds = std::chrono::duration<double>(Clock::now() - begun).count();
  return c;
}

}  // namespace oscar::replay
