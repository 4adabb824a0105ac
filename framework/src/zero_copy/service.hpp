#pragma once
// The iceoryx service description of a topic (internal to src/zero_copy).

#include <string>

#include <fmt/format.h>
#include <iceoryx_posh/capro/service_description.hpp>

namespace oscar::zero_copy::internal {

/// ("oscar", topic, type): one iceoryx service per OSCAR topic, the type as its event, so a
/// subscriber of another type never connects.
/// @throws std::invalid_argument if the topic or the type name is longer than iceoryx's 100.
inline iox::capro::ServiceDescription service_for(const std::string& topic,
                                                  const std::string& type_name) {
  using Id = iox::capro::IdString_t;
  for (const auto* text : {&topic, &type_name})
    if (text->empty() || text->size() > Id::capacity())
      throw std::invalid_argument(
          fmt::format("zero-copy service '{}': topic and type names must have 1 to {} characters",
                      *text, Id::capacity()));
  return {"oscar", Id(iox::cxx::TruncateToCapacity, topic.c_str()),
          Id(iox::cxx::TruncateToCapacity, type_name.c_str())};
}

}  // namespace oscar::zero_copy::internal
