#pragma once
/// @file Samples whose bytes are no valid encoding of their topic's type (a participant sending
/// another layout under an OSCAR type name, a corrupt sender): every type support the framework
/// registers (DdsParticipant::topic) refuses them, so Fast DDS drops them instead of the process
/// aborting; this counts them per topic and logs them, at most one line per topic every 10 s.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

namespace spdlog {
class logger;
}

namespace oscar {

/// DataReader::take_next_sample, and what it dropped as malformed counted and logged under the
/// reader's topic (after the take, outside Fast DDS's locks). Every reader of the framework
/// takes its samples through this.
eprosima::fastrtps::types::ReturnCode_t take_next(eprosima::fastdds::dds::DataReader& reader,
                                                  void* data,
                                                  eprosima::fastdds::dds::SampleInfo& info);

/// How many malformed samples this process has dropped on `topic` so far ("type <name>": those
/// of a type refused outside take_next(), e.g. a cue inside a pull reply).
std::uint64_t malformed_sample_count(const std::string& topic);

/// Where the lines about malformed samples go from now on (a module's logger, so that they
/// reach oscar/log too); until then, and after nullptr, spdlog's default logger.
void set_malformed_sample_log(std::shared_ptr<spdlog::logger> log);

namespace internal {
/// Called by the type support that refused a sample of `type`, saying why: counted under the
/// topic of the take_next() under way on this thread, else under "type <type>".
void note_malformed_sample(std::string_view type, std::string_view why);
}  // namespace internal

}  // namespace oscar
