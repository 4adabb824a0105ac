#pragma once
// The QoS both Fast DDS programs of `oscar bench cueflow` give their writer and reader, that of
// a module's output and input: reliable, keep last 16 (as bench_sink's input), volatile.
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

namespace oscar::bench {

template <class Q>
Q with_cue_qos(Q q) {
  namespace fdds = eprosima::fastdds::dds;
  q.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 16;
  q.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  return q;
}

}  // namespace oscar::bench
