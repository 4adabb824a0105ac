#pragma once
/// @file Typed readers and writers for the system topics (oscar/registry/..., oscar/system/...,
/// oscar/log) with the QoS classes of docs/architecture.md: state (reliable, transient-local, keep
/// last), heartbeats (manual-by-topic liveliness with a lease), events (reliable, transient-local).

#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/input.hpp"
#include "oscar/malformed_samples.hpp"
#include "oscar/topics.hpp"

namespace oscar {

struct OutputOptions;

/// QoS of the system topics; all allocate samples as large as they are (no preallocation).
namespace qos {
/// Reliable, transient-local, keep last `depth`: late joiners get the recent history.
eprosima::fastdds::dds::DataWriterQos state_writer(int depth = 1);
eprosima::fastdds::dds::DataReaderQos state_reader(int depth = 1);
/// Reliable, volatile, keep last `depth`: a stream for whoever listens now (oscar/log).
eprosima::fastdds::dds::DataWriterQos stream_writer(int depth);
eprosima::fastdds::dds::DataReaderQos stream_reader(int depth);
/// Reliable, volatile, keep all: commands, none of which may be dropped (oscar/config/...).
eprosima::fastdds::dds::DataWriterQos command_writer();
eprosima::fastdds::dds::DataReaderQos command_reader();
/// Reliable, volatile, keep last `depth`: the reader of requests anyone may write (a module's
/// configuration commands). Its listener takes each sample as it comes, so nothing is replaced
/// unless a writer outruns it; then the oldest go, instead of the reader's history growing
/// without bound. Matches command_writer().
eprosima::fastdds::dds::DataReaderQos request_reader(int depth);
/// Reliable, keep last 1, manual-by-topic liveliness with `lease`.
eprosima::fastdds::dds::DataWriterQos beat_writer(std::chrono::milliseconds lease);
eprosima::fastdds::dds::DataReaderQos beat_reader(std::chrono::milliseconds lease);
/// A kernel output's cue writer: keep last `depth`, reliable or best effort, volatile or
/// transient-local as the options say, written synchronously.
eprosima::fastdds::dds::DataWriterQos cue_writer(const OutputOptions& o);
/// The reader of an input fed by an output declared `producer` (cue_writer's other half), keeping
/// the last `depth` cues. DDS matches a reader only if the writer offers at least what it
/// requests: so it is reliable only if the producer is (and the input does not read best effort),
/// and transient-local only if the producer is (then it gets the producer's history).
eprosima::fastdds::dds::DataReaderQos cue_reader(const OutputOptions& producer, std::size_t depth,
                                                 Reliability input);
}  // namespace qos

/// Calls `on_sample` for every valid sample (on a DDS thread) and `on_lost` when a writer's
/// liveliness lapses (with the writer's instance handle, as SampleInfo::publication_handle).
template <class T, class PubSubType>
class TopicReader final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  using OnSample = std::function<void(const T&, const eprosima::fastdds::dds::SampleInfo&)>;
  using OnLost = std::function<void(const eprosima::fastdds::dds::InstanceHandle_t&)>;

  TopicReader(DdsParticipant& p, const std::string& topic,
              const eprosima::fastdds::dds::DataReaderQos& qos, OnSample on_sample,
              OnLost on_lost = {})
      : participant_(p), on_sample_(std::move(on_sample)), on_lost_(std::move(on_lost)) {
    create(topic, qos);
  }
  /// A reader of a catalogue topic (oscar/topics.hpp), with the catalogue's QoS.
  TopicReader(DdsParticipant& p, const TopicSpec<T, PubSubType>& spec, OnSample on_sample,
              OnLost on_lost = {})
      : TopicReader(p, spec.name, spec.reader_qos, std::move(on_sample), std::move(on_lost)) {}
  ~TopicReader() override { participant_.subscriber().delete_datareader(reader_); }
  TopicReader(const TopicReader&) = delete;
  TopicReader& operator=(const TopicReader&) = delete;

  int matched() const { return matched_.load(); }

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    T sample;
    eprosima::fastdds::dds::SampleInfo info;
    while (take_next(*reader, &sample, info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) on_sample_(sample, info);
    }
  }
  void on_subscription_matched(
      eprosima::fastdds::dds::DataReader*,
      const eprosima::fastdds::dds::SubscriptionMatchedStatus& status) override {
    matched_ = status.current_count;
  }
  void on_liveliness_changed(
      eprosima::fastdds::dds::DataReader*,
      const eprosima::fastdds::dds::LivelinessChangedStatus& status) override {
    if (on_lost_ && status.not_alive_count_change > 0) on_lost_(status.last_publication_handle);
  }

 private:
  void create(const std::string& topic, const eprosima::fastdds::dds::DataReaderQos& qos) {
    namespace dds = eprosima::fastdds::dds;
    auto mask = dds::StatusMask::data_available() << dds::StatusMask::subscription_matched();
    if (on_lost_) mask << dds::StatusMask::liveliness_changed();
    reader_ = participant_.subscriber().create_datareader(
        &participant_.topic(topic, new PubSubType()), qos, this, mask);
    if (!reader_) throw std::runtime_error("cannot create a reader for " + topic);
  }

  DdsParticipant& participant_;
  OnSample on_sample_;
  OnLost on_lost_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  std::atomic<int> matched_{0};
};

template <class T, class PubSubType>
class TopicWriter {
 public:
  TopicWriter(DdsParticipant& p, const std::string& topic,
              const eprosima::fastdds::dds::DataWriterQos& qos)
      : participant_(p) {
    writer_ = p.publisher().create_datawriter(&p.topic(topic, new PubSubType()), qos);
    if (!writer_) {
      throw std::runtime_error("cannot create a writer for " + topic + p.permission_hint(topic));
    }
  }
  /// A writer of a catalogue topic (oscar/topics.hpp), with the catalogue's QoS.
  TopicWriter(DdsParticipant& p, const TopicSpec<T, PubSubType>& spec)
      : TopicWriter(p, spec.name, spec.writer_qos) {}
  ~TopicWriter() { participant_.publisher().delete_datawriter(writer_); }
  TopicWriter(const TopicWriter&) = delete;
  TopicWriter& operator=(const TopicWriter&) = delete;

  /// False if DDS refused the sample (it logs why).
  bool write(const T& sample) { return writer_->write(const_cast<T*>(&sample)); }
  /// The DDS writer, for code that hands it on (the module's log sink).
  eprosima::fastdds::dds::DataWriter& dds_writer() { return *writer_; }
  int matched() const {
    eprosima::fastdds::dds::PublicationMatchedStatus s;
    writer_->get_publication_matched_status(s);
    return s.current_count;
  }

 private:
  DdsParticipant& participant_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
};

}  // namespace oscar
