#include "oscar/raw_cdr_type.hpp"

#include <cstring>

namespace oscar {

RawCdrType::RawCdrType(const std::string& type_name) {
  setName(type_name.c_str());
  // The reader's history reallocates for bigger samples; this is only the initial size.
  m_typeSize = 4096;
  m_isGetKeyDefined = false;
}

bool RawCdrType::serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) {
  const auto& s = *static_cast<RawSample*>(data);
  if (s.bytes.size() < 4 || payload->max_size < s.bytes.size()) return false;
  std::memcpy(payload->data, s.bytes.data(), s.bytes.size());
  payload->length = static_cast<std::uint32_t>(s.bytes.size());
  // The first two bytes are the encapsulation identifier: keep the writer's endianness.
  payload->encapsulation = (s.bytes[1] & 1) ? CDR_LE : CDR_BE;
  return true;
}

bool RawCdrType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) {
  auto& s = *static_cast<RawSample*>(data);
  s.bytes.assign(payload->data, payload->data + payload->length);
  return true;
}

std::function<std::uint32_t()> RawCdrType::getSerializedSizeProvider(void* data) {
  return [data] { return static_cast<std::uint32_t>(static_cast<RawSample*>(data)->bytes.size()); };
}

void* RawCdrType::createData() { return new RawSample(); }

void RawCdrType::deleteData(void* data) { delete static_cast<RawSample*>(data); }

bool RawCdrType::getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) { return false; }

}  // namespace oscar
