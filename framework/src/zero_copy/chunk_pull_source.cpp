#include "zero_copy/chunk_pull_source.hpp"

#include <algorithm>

#include "zero_copy/chunk_publisher.hpp"

namespace oscar::zero_copy {

ChunkPullSource::ChunkPullSource(const std::string& topic, const std::string& source,
                                 InputPort& consumer)
    : mirror_(source.substr(0, source.find('/')), source.substr(source.find('/') + 1),
              consumer.type(), OutputOptions{.depth = consumer.buffer().depth()}),
      pulls_(mirror_.buffer(), consumer, &mirror_),
      feed_(
          topic, consumer.type(), consumer.buffer().depth(),
          std::min(consumer.buffer().depth(), kMaxChunkHistory),
          [this](std::shared_ptr<const void> cue) { mirror_.forward_erased(std::move(cue)); },
          "pulls of input " + consumer.kernel() + "/" + consumer.name()) {}

}  // namespace oscar::zero_copy
