#include "oscar/registry/clock_topics.hpp"

#include "oscar/topic_io.hpp"

namespace oscar::topics {

TopicSpec<ClockProbe, ClockProbePubSubType> clock_probe() {
  return {"oscar/registry/clock/probe", qos::stream_writer(16), qos::stream_reader(16)};
}

TopicSpec<ClockEcho, ClockEchoPubSubType> clock_echo() {
  return {"oscar/registry/clock/echo", qos::stream_writer(16), qos::stream_reader(16)};
}

TopicSpec<HostClock, HostClockPubSubType> host_clocks() {
  return {"oscar/registry/clocks", qos::state_writer(1), qos::state_reader(64)};
}

}  // namespace oscar::topics
