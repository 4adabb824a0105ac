#include "zero_copy/chunk_identity.hpp"

#include <iceoryx_hoofs/internal/relocatable_pointer/base_relative_pointer.hpp>
#include <iceoryx_posh/mepoo/chunk_header.hpp>

namespace oscar::zero_copy {

std::optional<ChunkIdentity> identify_chunk(const void* payload) {
  using iox::rp::BaseRelativePointer;
  const auto segment = BaseRelativePointer::searchId(const_cast<void*>(payload));
  // iceoryx 2.0 answers 0 ("a regular pointer") for an address in none of its segments.
  if (segment == 0 || segment == BaseRelativePointer::NULL_POINTER_ID) return std::nullopt;
  ChunkIdentity identity;
  identity.segment = segment;
  identity.offset = BaseRelativePointer::getOffset(segment, payload);
  identity.sequence = iox::mepoo::ChunkHeader::fromUserPayload(payload)->sequenceNumber();
  return identity;
}

}  // namespace oscar::zero_copy
