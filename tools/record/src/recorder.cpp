#include "recorder.hpp"

#include <fnmatch.h>

#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/malformed_samples.hpp"
#include "oscar/mcap/writer.hpp"
#include "oscar/raw_cdr_type.hpp"
#include "oscar/topics.hpp"
#include "oscar/type_texts.hpp"

namespace oscar::record {
namespace dds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

namespace {
constexpr std::uint64_t kMaxQueuedBytes = 512ull << 20;  // beyond this, samples are dropped
// How long the first sample of a type OSCAR does not define waits for its module's announcement.
constexpr std::chrono::milliseconds kTypeTextWait{1000};

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

// "<stem>_003<ext>" for the fourth file of a split recording.
std::string split_name(const std::string& output, int index) {
  const std::filesystem::path p(output);
  return (p.parent_path() /
          fmt::format("{}_{:03}{}", p.stem().string(), index, p.extension().string()))
      .string();
}
}  // namespace

std::string topic_of(const std::string& argument) {
  return argument.rfind("oscar/", 0) == 0 ? argument : topics::cue(argument);
}

struct Recorder::Impl {
  struct Sample {
    std::size_t topic;
    std::uint64_t log_time;
    RawCue cue;  // its bytes and the header read from them
  };
  struct Topic {
    std::string name, type, qos;
    dds::DataReader* reader = nullptr;
  };
  // Receives one topic's samples on Fast DDS's thread and queues them for the writing thread.
  class Listener final : public dds::DataReaderListener {
   public:
    Listener(Impl& impl, std::size_t topic) : impl_(impl), topic_(topic) {}
    void on_data_available(dds::DataReader* reader) override {
      RawCue s;
      dds::SampleInfo info;
      while (take_next(*reader, &s, info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) impl_.push(topic_, std::move(s));
      }
    }
    void on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& status) override {
      impl_.dropped_ += static_cast<std::uint64_t>(status.total_count_change);
    }

   private:
    Impl& impl_;
    std::size_t topic_;
  };

  RecorderOptions o;
  std::map<std::size_t, std::uint16_t> channel_of;  // topic index -> channel id in this file
  std::map<std::string, std::uint16_t> schema_of;   // type -> schema id in this file
  std::set<std::string> without_schema;             // types said to have no IDL text
  std::vector<std::string> files;
  std::uint64_t file_start_time = 0;
  // The file before the participant (open_file() uses the members above): an unwritable path
  // fails before anything joins the domain.
  std::unique_ptr<mcap::Writer> writer;
  DdsParticipant participant;
  // The IDL texts of types OSCAR does not define, as their modules announce them.
  AnnouncedTypes announced{participant};
  std::vector<Topic> topics;
  std::vector<std::unique_ptr<Listener>> listeners;
  std::mutex mutex;
  std::deque<Sample> queue;
  std::uint64_t queued_bytes = 0;
  std::atomic<std::uint64_t> received_{0}, dropped_{0};
  std::uint64_t written = 0, bytes = 0;

  explicit Impl(RecorderOptions options)
      : o(std::move(options)), writer(open_file()), participant(o.domain, "oscar-record") {}

  ~Impl() {
    for (auto& t : topics) {
      if (t.reader) participant.subscriber().delete_datareader(t.reader);
    }
  }

  void push(std::size_t topic, RawCue cue) {
    ++received_;
    std::lock_guard lock(mutex);
    if (queued_bytes + cue.cdr.size() > kMaxQueuedBytes) {
      ++dropped_;
      return;
    }
    queued_bytes += cue.cdr.size();
    queue.push_back({topic, now_ns(), std::move(cue)});
  }

  bool wanted(const std::string& topic) const {
    if (o.all && topics::is_cue(topic)) return true;
    for (const auto& t : o.topics) {
      if (fnmatch(topic_of(t).c_str(), topic.c_str(), 0) == 0) return true;
    }
    return false;
  }

  void discover() {
    for (const auto& [name, w] : participant.discovered_writers()) {
      if (!wanted(name)) continue;
      bool known = false;
      for (const auto& t : topics) known = known || t.name == name;
      if (known) continue;
      auto& topic = participant.topic(name, new RawCdrType(w.type));
      dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
      q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
      q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
      q.history().depth = 64;
      q.durability().kind = dds::VOLATILE_DURABILITY_QOS;
      listeners.push_back(std::make_unique<Listener>(*this, topics.size()));
      auto* reader = participant.subscriber().create_datareader(
          &topic, q, listeners.back().get(),
          dds::StatusMask::data_available() << dds::StatusMask::sample_lost());
      if (!reader) throw std::runtime_error("cannot subscribe to " + name);
      topics.push_back({name, w.type, w.qos, reader});
      fmt::print(stderr, "{}recording {} ({})\n", o.progress ? "\r\033[K" : "", name, w.type);
    }
  }

  // Creates the next file of the recording; its schemas and channels are added as used.
  std::unique_ptr<mcap::Writer> open_file() {
    const auto path = (o.split_size_bytes || o.split_duration.count())
                          ? split_name(o.output, static_cast<int>(files.size()))
                          : o.output;
    mcap::WriterOptions w;
    w.compression = o.compression;
    w.chunk_size_bytes = o.chunk_size_bytes;
    w.library = "oscar-record";
    auto next = std::make_unique<mcap::Writer>(path, w);
    files.push_back(path);
    channel_of.clear();
    schema_of.clear();
    file_start_time = 0;
    return next;
  }

  std::uint16_t channel(std::size_t index) {
    if (auto it = channel_of.find(index); it != channel_of.end()) return it->second;
    const auto& t = topics[index];
    std::uint16_t schema = 0;
    if (auto s = schema_of.find(t.type); s != schema_of.end()) {
      schema = s->second;
    } else if (auto idl = without_schema.contains(t.type)
                              ? announced.idl_text(t.type)
                              : announced.wait_for(t.type, kTypeTextWait)) {
      // A type of a module's own: its announcement normally came before its first cue.
      schema = writer->add_schema(t.type, "omgidl", {idl->begin(), idl->end()});
      schema_of[t.type] = schema;
    } else if (without_schema.insert(t.type).second) {
      fmt::print(stderr,
                 "{}{} ({}) is recorded without a schema: OSCAR does not define its type and no "
                 "module announced its IDL text\n",
                 o.progress ? "\r\033[K" : "", t.name, t.type);
    }
    std::map<std::string, std::string> meta{{"type", t.type}, {"qos", t.qos}};
    // oscar/cue/<kernel>/<channel>
    if (topics::is_cue(t.name)) {
      const auto rest = t.name.substr(10);
      const auto slash = rest.find('/');
      meta["kernel"] = rest.substr(0, slash);
      if (slash != std::string::npos) meta["channel"] = rest.substr(slash + 1);
    }
    return channel_of[index] = writer->add_channel(schema, t.name, "cdr", meta);
  }

  void write(const Sample& s) {
    if (writer &&
        ((o.split_size_bytes && writer->bytes_written() >= o.split_size_bytes) ||
         (o.split_duration.count() && file_start_time &&
          s.log_time - file_start_time >= static_cast<std::uint64_t>(o.split_duration.count())))) {
      writer->close();
      writer = open_file();
    }
    if (!file_start_time) file_start_time = s.log_time;
    // A payload without a readable header has an empty one: sequence 0, published when logged.
    const auto& header = s.cue.header();
    mcap::MessageView m;
    m.channel_id = channel(s.topic);
    m.sequence = static_cast<std::uint32_t>(header.seq());
    m.log_time = s.log_time;
    const auto generated = static_cast<std::uint64_t>(generation_stamp(header));
    m.publish_time = generated ? generated : s.log_time;
    m.data = s.cue.cdr;
    writer->write(m);
    ++written;
    bytes += s.cue.cdr.size();
  }

  // Writes what is queued; returns the number of samples written.
  std::size_t drain() {
    std::deque<Sample> batch;
    {
      std::lock_guard lock(mutex);
      batch.swap(queue);
      queued_bytes = 0;
    }
    for (const auto& s : batch) write(s);
    return batch.size();
  }

  void progress(double rate) {
    std::fprintf(stderr, "\r\033[K%llu msgs  %.1f MB  %.0f msg/s  %llu dropped  (%zu topics)",
                 static_cast<unsigned long long>(written), bytes / 1e6, rate,
                 static_cast<unsigned long long>(dropped_.load()), topics.size());
    std::fflush(stderr);
  }
};

Recorder::Recorder(RecorderOptions options) {
  if (!options.all && options.topics.empty()) {
    throw std::invalid_argument("nothing to record: name topics (or globs) or give --all");
  }
  impl_ = std::make_unique<Impl>(std::move(options));
}

Recorder::~Recorder() = default;

void Recorder::run(const std::atomic<bool>& stop) {
  auto& d = *impl_;
  auto last_discovery = Clock::now() - std::chrono::seconds(1);
  auto last_progress = Clock::now(), last_flush = Clock::now();
  std::uint64_t written_at_progress = 0;
  while (!stop) {
    const auto now = Clock::now();
    if (now - last_discovery > std::chrono::milliseconds(100)) {
      d.discover();
      last_discovery = now;
    }
    d.drain();
    if (now - last_flush > d.o.max_chunk_age) {
      d.writer->flush();  // bounds what a killed recorder loses
      last_flush = now;
    }
    if (d.o.progress && now - last_progress > std::chrono::milliseconds(500)) {
      const double seconds = std::chrono::duration<double>(now - last_progress).count();
      d.progress((d.written - written_at_progress) / seconds);
      written_at_progress = d.written;
      last_progress = now;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Stop receiving, write what came in, finish the file.
  for (auto& t : d.topics) {
    d.participant.subscriber().delete_datareader(t.reader);
    t.reader = nullptr;
  }
  d.drain();
  if (d.o.progress) std::fputs("\n", stderr);
  d.writer->close();
}

RecorderCounters Recorder::counters() const {
  return {impl_->received_.load(), impl_->written, impl_->dropped_.load(), impl_->bytes};
}

const std::vector<std::string>& Recorder::files() const { return impl_->files; }

}  // namespace oscar::record
