#include "dds/guarded_type.hpp"

#include <exception>
#include <span>

#include "oscar/malformed_samples.hpp"

namespace oscar::internal {

GuardedType::GuardedType(eprosima::fastdds::dds::TopicDataType* inner, WireCheck check)
    : inner_(inner), check_(check) {
  setName(inner_->getName());
  m_typeSize = inner_->m_typeSize;
  m_isGetKeyDefined = inner_->m_isGetKeyDefined;
  auto_fill_type_object(inner_->auto_fill_type_object());
  auto_fill_type_information(inner_->auto_fill_type_information());
}

bool GuardedType::serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) {
  return inner_->serialize(data, payload);
}

bool GuardedType::deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) {
  if (check_) {
    const std::span<const std::uint8_t> bytes(payload->data, payload->length);
    if (const auto why = check_(bytes)) {
      note_malformed_sample(getName(), *why);
      return false;
    }
  }
  // Whatever the decoder throws (Fast CDR's exceptions, std::bad_alloc, a length error), the
  // sample is refused: a sender must not be able to end this process.
  try {
    if (inner_->deserialize(payload, data)) return true;
    note_malformed_sample(getName(), "its type support refused it");
  } catch (const std::exception& e) {
    note_malformed_sample(getName(), e.what());
  } catch (...) {
    note_malformed_sample(getName(), "its type support threw");
  }
  return false;
}

std::function<std::uint32_t()> GuardedType::getSerializedSizeProvider(void* data) {
  return inner_->getSerializedSizeProvider(data);
}

void* GuardedType::createData() { return inner_->createData(); }

void GuardedType::deleteData(void* data) { inner_->deleteData(data); }

bool GuardedType::getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle,
                         bool force_md5) {
  return inner_->getKey(data, handle, force_md5);
}

bool GuardedType::is_bounded() const { return inner_->is_bounded(); }

bool GuardedType::is_plain() const { return inner_->is_plain(); }

bool GuardedType::construct_sample(void* memory) const { return inner_->construct_sample(memory); }

}  // namespace oscar::internal
