// The cue QoS classes (docs/architecture.md, "Topics and QoS classes"): the reader of an input asks
// what its producer offers.
#include "oscar/topic_io.hpp"

#include <gtest/gtest.h>

#include "oscar/output.hpp"

namespace oscar {
namespace {
namespace dds = eprosima::fastdds::dds;

TEST(CueQos, AReaderIsReliableAndDurableExactlyAsItsProducer) {
  for (const bool reliable : {true, false}) {
    for (const bool transient_local : {true, false}) {
      const OutputOptions producer{
          .depth = 4, .reliable = reliable, .transient_local = transient_local};
      const auto writer = qos::cue_writer(producer);
      const auto reader = qos::cue_reader(producer, 32, Reliability::kAsProducer);
      EXPECT_EQ(reader.reliability().kind, writer.reliability().kind);
      EXPECT_EQ(reader.durability().kind, writer.durability().kind);
      EXPECT_EQ(reader.history().kind, dds::KEEP_LAST_HISTORY_QOS);
      EXPECT_EQ(reader.history().depth, 32) << "the input's depth, not the output's";
    }
  }
}

TEST(CueQos, AnInputThatReadsBestEffortDoesSoFromAReliableProducer) {
  const auto reader = qos::cue_reader(OutputOptions{}, 16, Reliability::kBestEffort);
  EXPECT_EQ(reader.reliability().kind, dds::BEST_EFFORT_RELIABILITY_QOS);
}

TEST(CueQos, CuesTravelSerializedWithoutFastDdsDataSharing) {
  // Fast DDS's default (automatic) would share the plain types' cues through /dev/shm pools.
  EXPECT_EQ(qos::cue_writer(OutputOptions{}).data_sharing().kind(), dds::OFF);
  EXPECT_EQ(qos::cue_reader(OutputOptions{}, 16, Reliability::kAsProducer).data_sharing().kind(),
            dds::OFF);
}

}  // namespace
}  // namespace oscar
