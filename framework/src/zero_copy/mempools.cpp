#include "zero_copy/mempools.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <iceoryx_posh/mepoo/chunk_settings.hpp>

namespace oscar::zero_copy {

std::uint32_t chunk_bytes_for(std::size_t bytes, std::size_t alignment) {
  const auto refuse = [&] {
    return std::invalid_argument(fmt::format(
        "a zero-copy chunk for {} bytes aligned to {}: iceoryx cannot hold it in one chunk", bytes,
        alignment));
  };
  constexpr auto kMax = std::numeric_limits<std::uint32_t>::max();
  if (bytes > kMax || alignment > kMax) throw refuse();
  const auto settings = iox::mepoo::ChunkSettings::create(static_cast<std::uint32_t>(bytes),
                                                          static_cast<std::uint32_t>(alignment));
  if (settings.has_error()) throw refuse();
  // RouDi's mempools take chunk sizes in multiples of 8 (MemPool::CHUNK_MEMORY_ALIGNMENT).
  return (settings.value().requiredChunkSize() + 7U) / 8U * 8U;
}

std::vector<Mempool> plain_cue_mempools(std::uint32_t count) {
  return {mempool_for<oscar::PlainBool>(count), mempool_for<oscar::PlainLineSeg3DSeq>(count),
          mempool_for<oscar::PlainGvImage>(count)};
}

std::string roudi_config(std::vector<Mempool> pools) {
  if (pools.empty()) throw std::invalid_argument("RouDi's configuration needs a mempool");
  std::sort(pools.begin(), pools.end(),
            [](const Mempool& a, const Mempool& b) { return a.chunk_bytes < b.chunk_bytes; });
  std::vector<Mempool> merged;
  for (const auto& pool : pools) {
    if (pool.count == 0 || pool.chunk_bytes == 0)
      throw std::invalid_argument(fmt::format(
          "mempool of {} chunks of {} bytes: each needs at least one chunk of at least 8 bytes",
          pool.count, pool.chunk_bytes));
    if (!merged.empty() && merged.back().chunk_bytes == pool.chunk_bytes)
      merged.back().count += pool.count;
    else
      merged.push_back(pool);
  }
  std::string text = "[general]\nversion = 1\n\n[[segment]]\n";
  for (const auto& pool : merged)
    text +=
        fmt::format("\n[[segment.mempool]]\nsize = {}\ncount = {}\n", pool.chunk_bytes, pool.count);
  return text;
}

}  // namespace oscar::zero_copy
