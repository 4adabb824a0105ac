#include "replayer.hpp"

#include <fnmatch.h>

#include <cstdio>
#include <iostream>
#include <map>
#include <thread>

#include <fmt/format.h>
#include <fastdds/dds/publisher/DataWriter.hpp>

#include "lanes.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/mcap/reader.hpp"
#include "oscar/output.hpp"
#include "oscar/process_util.hpp"
#include "oscar/raw_cdr_type.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/type_texts.hpp"
#include "reading_priority.hpp"
#include "recorder.hpp"  // topic_of

namespace oscar::replay {
namespace dds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

namespace {
struct Stopped {};                               // ends a scan early
constexpr std::size_t kMaxLaneParticipants = 8;  // topics beyond share them
// Reading runs this far ahead of the publishing (a 1.7 MB chunk of images takes milliseconds to
// read and check); once full, it waits until half of it is published.
constexpr std::size_t kReadAheadBytes = std::size_t{16} << 20;
constexpr std::size_t kMaxPrefaultBytes = std::size_t{1} << 30;
}  // namespace

struct Replayer::Impl {
  ReplayOptions o;
  mcap::Reader reader;
  mcap::FileInfo info;
  std::optional<DdsParticipant> participant;  // the one that checks types against discovery
  // Writers on participants of their own: Fast DDS sends a participant's messages one at a time,
  // and a 45-byte cue waited up to 5 ms behind the fragments of four images.
  std::vector<std::unique_ptr<DdsParticipant>> lanes;
  std::map<std::uint16_t, std::pair<DdsParticipant*, dds::DataWriter*>> writers;  // by channel
  // The recorded IDL texts of types OSCAR does not define, announced as their module did.
  std::unique_ptr<TypeTextsWriter> types_writer;
  static constexpr std::size_t kHistoryDepth = OutputOptions{}.depth;

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
      participant->topic(tt.first, new RawCdrType(tt.second));  // throws on a mismatch
      if (lanes.size() < kMaxLaneParticipants) {
        lanes.push_back(std::make_unique<DdsParticipant>(o.domain, "oscar-replay"));
      }
      auto& lane = *lanes[writers.size() % lanes.size()];
      auto& topic = lane.topic(tt.first, new RawCdrType(tt.second));
      auto* w = lane.publisher().create_datawriter(&topic, qos::cue_writer(OutputOptions{}));
      if (!w) throw std::runtime_error("cannot create a writer for " + tt.first);
      writers[id] = {&lane, w};
      fmt::print(stderr, "replaying {} as {} ({})\n", info.channels.at(id).topic, tt.first,
                 tt.second);
    }
    announce_own_types();
  }

  // A module announced the IDL texts of its own types (oscar/type_texts.hpp), and the recorder
  // kept them as schemas: announced again, the tools decode the replayed cues as the recorded.
  void announce_own_types() {
    std::map<std::string, std::string> texts;
    for (const auto& [id, w] : writers) {
      const auto s = info.schemas.find(info.channels.at(id).schema_id);
      if (s != info.schemas.end() && s->second.encoding == "omgidl" &&
          !idl_texts().contains(s->second.name)) {
        texts[s->second.name] = std::string(s->second.data.begin(), s->second.data.end());
      }
    }
    types_writer = announce_type_texts(*participant, "oscar-replay", texts);
  }

  ~Impl() {
    for (auto& [id, w] : writers) w.first->publisher().delete_datawriter(w.second);
  }

  // The memory publishing will use: the read-ahead and each writer's history (depth + 1
  // messages of the largest size among the first messages of its topic). The scan ends once
  // every topic was seen or a read-ahead's worth was read (a topic not seen by then is small).
  std::size_t memory_needed() {
    std::map<std::uint16_t, std::size_t> largest;
    std::size_t scanned = 0;
    try {
      reader.read_messages([&](const mcap::Channel& ch, const mcap::MessageView& m) {
        scanned += m.data.size();
        if (writers.count(ch.id)) {
          auto& size = largest[ch.id];
          size = std::max(size, m.data.size());
        }
        if (largest.size() == writers.size() || scanned >= kReadAheadBytes) throw Stopped{};
      });
    } catch (const Stopped&) {
    }
    std::size_t bytes = kReadAheadBytes;
    for (const auto& [id, size] : largest) bytes += (kHistoryDepth + 1) * size;
    return std::min(bytes, kMaxPrefaultBytes);
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
        w.second->get_publication_matched_status(status);
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
  // Fresh memory costs a page fault per 4 KB when first written (about 1 ms for a 442 KB image
  // on a virtual machine): touch it now, so that the first images are not published late.
  if (!d.o.step) prefault_heap(d.memory_needed());
  d.wait_for_readers();
  ReplayCounters c;
  c.topics = d.writers.size();
  // The first messages are due a moment after the start: time to start the lanes and read
  // ahead (the first ones were published up to 28 ms late without it).
  const auto begun = Clock::now() + std::chrono::milliseconds(d.o.step ? 0 : 100);
  const std::uint64_t first = d.info.statistics.message_start_time;
  const std::uint64_t from = first + (d.o.start ? d.o.start->count() : 0);
  const std::uint64_t to = d.o.end ? first + d.o.end->count() : UINT64_MAX;
  std::map<dds::DataWriter*, RawCue> samples;  // each used by its writer's lane only
  for (const auto& [id, w] : d.writers) samples[w.second];
  std::function<bool(const Pending&)> step;
  if (d.o.step) {
    step = [&](const Pending& p) {
      fmt::print(stderr, "{}; Enter publishes it", p.label);
      std::string line;
      return static_cast<bool>(std::getline(std::cin, line));
    };
  }
  // Each topic is published by a thread of its own, started before this thread's priority is
  // lowered; this thread reads, in the background while it is far ahead.
  std::vector<const void*> keys;
  for (const auto& [id, w] : d.writers) keys.push_back(d.o.step ? nullptr : w.second);
  std::optional<ReadingPriority> priority;
  if (!d.o.step) priority.emplace();
  ReadingPace pace;
  if (priority && priority->available()) {
    pace.ahead = [&] { priority->background(); };
    pace.behind = [&] { priority->normal(); };
  }
  Lanes lanes(keys, begun, kReadAheadBytes, stop, step, pace);
  const auto scaled = [&](std::uint64_t ns) {
    return std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(ns) / d.o.rate));
  };
  std::chrono::nanoseconds pass_start{0};  // the replay's clock at the start of this pass
  std::uint64_t read = 0;
  try {
    do {
      std::uint64_t last = from;
      d.reader.read_messages([&](const mcap::Channel& ch, const mcap::MessageView& m) {
        const auto w = d.writers.find(ch.id);
        if (w == d.writers.end() || m.log_time < from || m.log_time > to) return;
        last = m.log_time;
        Pending p;
        const auto writer = w->second.second;
        p.lane = d.o.step ? nullptr : writer;  // stepping: one lane, in file order
        p.due = pass_start + scaled(m.log_time - from);
        p.bytes.assign(m.data.begin(), m.data.end());
        p.publish = [writer, sample = &samples[writer]](auto& bytes) {
          sample->cdr.swap(bytes);
          writer->write(sample);
        };
        if (d.o.step) {
          p.label = fmt::format("[{}] {} seq {} at +{:.3f} s", read + 1, ch.topic, m.sequence,
                                (m.log_time - first) / 1e9);
        }
        if (!lanes.add(std::move(p))) throw Stopped{};
        if (d.o.progress && ++read % 50 == 0) {
          std::fprintf(stderr, "\r\033[K%llu published  +%.1f s",
                       static_cast<unsigned long long>(lanes.published()),
                       std::chrono::duration<double>(Clock::now() - begun).count());
        }
      });
      pass_start += scaled(last - from);
    } while (d.o.loop && !stop);
  } catch (const Stopped&) {
  }
  lanes.drain();
  c.published = lanes.published();
  c.late_us_p50 = lanes.lateness_us(0.5);
  c.late_us_p99 = lanes.lateness_us(0.99);
  c.late_us_max = lanes.lateness_us(1.0);
  if (d.o.progress) std::fputs("\n", stderr);
  // Reliable writers: give late acknowledgements a moment before the participant goes.
  for (auto& [id, w] : d.writers) {
    w.second->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
  }
  c.seconds = std::chrono::duration<double>(Clock::now() - begun).count();
  return c;
}

}  // namespace oscar::replay
