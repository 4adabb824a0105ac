#pragma once
// ClientQueue: what waits to be sent to one bridge client, bounded. A client that reads slower
// than the system writes loses the oldest messages of a channel, never the newest, and never
// holds anything up: each drop is counted per channel so the bridge can report it.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <vector>

namespace oscar::bridge {

struct QueueLimits {
  std::size_t messages_per_channel = 16;  ///< beyond this, the channel's oldest is dropped
  std::size_t bytes = 32u << 20;          ///< payload bytes of all channels together
};

class ClientQueue {
 public:
  /// One message as the bridge received it: the payload is shared by every client it goes to.
  struct Message {
    std::uint32_t channel = 0;
    std::shared_ptr<const std::vector<std::uint8_t>> payload;
    std::uint64_t receive_ns = 0;
  };

  explicit ClientQueue(QueueLimits limits = {}) : limits_(limits) {}

  /// Queues `message`; if that exceeds a limit, drops the oldest messages of its channel (then,
  /// if the bytes still exceed, of the other channel holding the most bytes) and counts them. The
  /// newest message is always kept, however large.
  void push(Message message);
  /// The message queued longest, across channels; nullopt when empty.
  std::optional<Message> pop();
  /// Forgets the queued messages of `channel` (its subscription ended); not counted as drops.
  void forget(std::uint32_t channel);

  std::size_t size() const { return size_; }
  std::size_t bytes() const { return bytes_; }
  /// Messages of `channel` dropped so far.
  std::uint64_t dropped(std::uint32_t channel) const;
  /// Drops per channel so far (channels with none are absent).
  const std::map<std::uint32_t, std::uint64_t>& drops() const { return drops_; }

 private:
  struct Entry {
    std::uint64_t order;  // arrival, across channels
    Message message;
  };
  void drop_oldest(std::uint32_t channel);
  std::uint32_t other_channel_with_most_bytes(std::uint32_t except) const;

  QueueLimits limits_;
  std::map<std::uint32_t, std::deque<Entry>> channels_;
  std::map<std::uint32_t, std::size_t> channel_bytes_;
  std::map<std::uint32_t, std::uint64_t> drops_;
  std::uint64_t next_order_ = 0;
  std::size_t size_ = 0;
  std::size_t bytes_ = 0;
};

}  // namespace oscar::bridge
