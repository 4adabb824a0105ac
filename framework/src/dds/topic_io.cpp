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
}  // namespace

dds::DataWriterQos state_writer(int depth) {
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
  q.endpoint().history_memory_policy = kDynamic;
  return q;
}

dds::DataReaderQos state_reader(int depth) {
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
  q.endpoint().history_memory_policy = kDynamic;
  return q;
}

dds::DataWriterQos stream_writer(int depth) {
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
  q.endpoint().history_memory_policy = kDynamic;
  return q;
}

dds::DataWriterQos command_writer() {
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  q.history().kind = dds::KEEP_ALL_HISTORY_QOS;
  q.endpoint().history_memory_policy = kDynamic;
  return q;
}

dds::DataReaderQos command_reader() {
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  q.history().kind = dds::KEEP_ALL_HISTORY_QOS;
  q.endpoint().history_memory_policy = kDynamic;
  return q;
}

dds::DataReaderQos stream_reader(int depth) {
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
  q.endpoint().history_memory_policy = kDynamic;
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
  return q;
}

}  // namespace oscar::qos
