#pragma once
/// @file RouDi's mempools for plain cues: chunks sized from the types (docs/zero_copy.md).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "zero_copy/plain_cue.hpp"

namespace oscar::zero_copy {

/// `count` chunks of `chunk_bytes` each (payload and iceoryx's chunk header).
struct Mempool {
  std::uint32_t chunk_bytes = 0;
  std::uint32_t count = 0;
};

/// The chunk size RouDi must offer for a payload of `bytes` aligned to `alignment`.
/// @throws std::invalid_argument if iceoryx cannot hold such a payload in one chunk.
std::uint32_t chunk_bytes_for(std::size_t bytes, std::size_t alignment);

/// A mempool of `count` chunks that each hold one cue of type T.
template <PlainCue T>
Mempool mempool_for(std::uint32_t count) {
  return {chunk_bytes_for(sizeof(T), alignof(T)), count};
}

/// Mempools for every plain cue type, `count` chunks each.
std::vector<Mempool> plain_cue_mempools(std::uint32_t count);

/// RouDi's configuration (`iox-roudi -c FILE`, TOML) with one shared-memory segment holding
/// `pools`: sorted by size, pools of one size merged (RouDi wants them ascending and distinct).
/// @throws std::invalid_argument for no pools or a pool without chunks.
std::string roudi_config(std::vector<Mempool> pools);

}  // namespace oscar::zero_copy
