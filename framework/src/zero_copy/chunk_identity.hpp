#pragma once
/// @file Where a cue lies in shared memory, comparable across processes: the same chunk has the
/// same segment and offset in every process that maps it, whatever address it is mapped at.

#include <cstdint>
#include <optional>

namespace oscar::zero_copy {

struct ChunkIdentity {
  std::uint64_t segment = 0;   ///< iceoryx's id of the shared-memory segment
  std::uint64_t offset = 0;    ///< the payload's byte offset inside that segment
  std::uint64_t sequence = 0;  ///< the chunk's sequence number (set by the publisher)
};

/// The identity of the chunk whose payload starts at `payload`; nothing if `payload` lies in no
/// shared-memory segment of this process (then it is a copy, not the producer's chunk).
std::optional<ChunkIdentity> identify_chunk(const void* payload);

}  // namespace oscar::zero_copy
