#include "oscar/topic_io.hpp"

#include <algorithm>

#include "oscar/output.hpp"

namespace oscar::qos {
namespace dds = eprosima::fastdds::dds;

namespace {
// The system types nest sequences (SystemState > ModuleState > KernelState > strings): their
// largest possible sample is hundreds of MB, and preallocated histories would reserve that many
// times over. Samples are allocated as large as they really are instead.
constexpr auto kDynamic = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;

eprosima::fastrtps::Duration_t seconds(std::chrono::milliseconds d) {
  return eprosima::fastrtps::Duration_t(static_cast<double>(d.count()) / 1000.0);
}

// Reliable, with the given durability and history, samples allocated as large as they are.
template <class Qos>
Qos reliable(Qos q, dds::DurabilityQosPolicyKind durability, dds::HistoryQosPolicyKind history,
             int depth = 1) {
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = durability;
  q.history().kind = history;
  q.history().depth = depth;
  q.endpoint().history_memory_policy = kDynamic;
  return q;
}
constexpr auto kTransientLocal = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
constexpr auto kVolatile = dds::VOLATILE_DURABILITY_QOS;
constexpr auto kKeepLast = dds::KEEP_LAST_HISTORY_QOS;
constexpr auto kKeepAll = dds::KEEP_ALL_HISTORY_QOS;
}  // namespace

dds::DataWriterQos state_writer(int depth) {
  return reliable(dds::DATAWRITER_QOS_DEFAULT, kTransientLocal, kKeepLast, depth);
}

dds::DataReaderQos state_reader(int depth) {
  return reliable(dds::DATAREADER_QOS_DEFAULT, kTransientLocal, kKeepLast, depth);
}

dds::DataWriterQos stream_writer(int depth) {
  return reliable(dds::DATAWRITER_QOS_DEFAULT, kVolatile, kKeepLast, depth);
}

dds::DataReaderQos stream_reader(int depth) {
  return reliable(dds::DATAREADER_QOS_DEFAULT, kVolatile, kKeepLast, depth);
}

dds::DataWriterQos command_writer() {
  return reliable(dds::DATAWRITER_QOS_DEFAULT, kVolatile, kKeepAll);
}

dds::DataReaderQos command_reader() {
  return reliable(dds::DATAREADER_QOS_DEFAULT, kVolatile, kKeepAll);
}

dds::DataReaderQos request_reader(int depth) {
  auto q = reliable(dds::DATAREADER_QOS_DEFAULT, kVolatile, kKeepLast, depth);
  // The limits say the same as the depth. Without them (Fast DDS 2.9.1's defaults, 5000
  // samples), a module's keep-last reader flooded by one writer delivered that writer's first
  // command and then nothing at all, from any writer.
  q.resource_limits().max_instances = 1;
  q.resource_limits().max_samples_per_instance = depth;
  q.resource_limits().max_samples = depth;
  return q;
}

dds::DataWriterQos beat_writer(std::chrono::milliseconds lease) {
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 1;
  q.endpoint().history_memory_policy = kDynamic;
  q.liveliness().kind = dds::MANUAL_BY_TOPIC_LIVELINESS_QOS;
  q.liveliness().lease_duration = seconds(lease);
  q.liveliness().announcement_period = seconds(lease / 3);
  return q;
}

dds::DataReaderQos beat_reader(std::chrono::milliseconds lease) {
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 1;
  q.endpoint().history_memory_policy = kDynamic;
  q.liveliness().kind = dds::MANUAL_BY_TOPIC_LIVELINESS_QOS;
  q.liveliness().lease_duration = seconds(lease);
  return q;
}

dds::DataWriterQos cue_writer(const OutputOptions& o) {
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind =
      o.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = static_cast<std::int32_t>(o.depth);
  q.durability().kind =
      o.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  q.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
  // Cues travel serialized through DDS. Fast DDS would otherwise share the cues of a plain
  // (bounded) type with same-host readers through a pool file per writer in /dev/shm
  // (fast_datasharing_<guid>, depth x 442 KB for PlainGvImage) that stays when the process is
  // killed; the same-host zero-copy path is iceoryx's (docs/zero_copy.md).
  q.data_sharing().off();
  return q;
}

dds::DataReaderQos cue_reader(const OutputOptions& producer, std::size_t depth, Reliability input) {
  const bool reliable = producer.reliable && input != Reliability::kBestEffort;
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind =
      reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = static_cast<std::int32_t>(std::max<std::size_t>(depth, 1));
  q.durability().kind =
      producer.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  q.data_sharing().off();  // as cue_writer
  return q;
}

}  // namespace oscar::qos
