#include "oscar/raw_cdr_type.hpp"

#include <cstring>

#include "oscar/cue_header_cdr.hpp"

namespace oscar {

RawCdrType::RawCdrType(const std::string& type_name) : layout_(cue_header_layout(type_name)) {
  setName(type_name.c_str());
  // The reader's history reallocates for bigger samples; this is only the initial size.
  m_typeSize = 4096;
  m_isGetKeyDefined = false;
}

bool RawCdrType::serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) {
  const auto& s = *static_cast<RawCue*>(data);
  if (s.cdr.size() < 4 || payload->max_size < s.cdr.size()) return false;
  std::memcpy(payload->data, s.cdr.data(), s.cdr.size());
  payload->length = static_cast<std::uint32_t>(s.cdr.size());
  // The first two bytes are the encapsulation identifier: keep the writer's endianness.
  payload->encapsulation = (s.cdr[1] & 1) ? CDR_LE : CDR_BE;
  return true;
}

bool RawCdrType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) {
  auto& s = *static_cast<RawCue*>(data);
  s.type = getName();
  s.cdr.assign(payload->data, payload->data + payload->length);
  s.cue_header = read_cue_header(s.cdr, layout_).value_or(CueHeader{});
  return true;
}

std::function<std::uint32_t()> RawCdrType::getSerializedSizeProvider(void* data) {
  return [data] { return static_cast<std::uint32_t>(static_cast<RawCue*>(data)->cdr.size()); };
}

void* RawCdrType::createData() { return new RawCue(); }

void RawCdrType::deleteData(void* data) { delete static_cast<RawCue*>(data); }

bool RawCdrType::getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) { return false; }

}  // namespace oscar
