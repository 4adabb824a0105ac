#include "client_queue.hpp"

#include "oscar/demand.hpp"

namespace oscar::bridge {
namespace {
std::size_t size_of(const ClientQueue::Message& m) { return m.payload ? m.payload->size() : 0; }
}  // namespace

void ClientQueue::push(Message message) {
  const auto channel = message.channel;
  const auto n = size_of(message);
  channels_[channel].push_back({next_order_++, std::move(message)});
  channel_bytes_[channel] += n;
  ++size_;
  bytes_ += n;
  while (channels_[channel].size() > limits_.messages_per_channel) drop_oldest(channel);
  // The newest message stays: with it alone over the budget, the client gets it or nothing.
  while (bytes_ > limits_.bytes && size_ > 1) {
    drop_oldest(channels_[channel].size() > 1 ? channel : other_channel_with_most_bytes(channel));
  }
}

std::optional<ClientQueue::Message> ClientQueue::pop() {
  std::deque<Entry>* oldest = nullptr;
  for (auto& [channel, entries] : channels_) {
    if (!entries.empty() && (!oldest || entries.front().order < oldest->front().order)) {
      oldest = &entries;
    }
  }
  if (!oldest) return std::nullopt;
  auto message = std::move(oldest->front().message);
  oldest->pop_front();
  const auto n = size_of(message);
  channel_bytes_[message.channel] -= n;
  bytes_ -= n;
  --size_;
  return message;
}

void ClientQueue::forget(std::uint32_t channel) {
  const auto it = channels_.find(channel);
  if (it == channels_.end()) return;
  size_ -= it->second.size();
  bytes_ -= channel_bytes_[channel];
  channels_.erase(it);
  channel_bytes_.erase(channel);
}

std::uint64_t ClientQueue::dropped(std::uint32_t channel) const {
  const auto it = drops_.find(channel);
  return it == drops_.end() ? 0 : it->second;
}

void ClientQueue::drop_oldest(std::uint32_t channel) {
  auto& entries = channels_[channel];
  OSCAR_DEMAND(!entries.empty(), "a channel with nothing queued has nothing to drop");
  const auto n = size_of(entries.front().message);
  entries.pop_front();
  channel_bytes_[channel] -= n;
  bytes_ -= n;
  --size_;
  ++drops_[channel];
}

std::uint32_t ClientQueue::other_channel_with_most_bytes(std::uint32_t except) const {
  std::uint32_t most = except;
  std::size_t most_bytes = 0;
  for (const auto& [channel, n] : channel_bytes_) {
    if (channel != except && n >= most_bytes && !channels_.at(channel).empty()) {
      most = channel;
      most_bytes = n;
    }
  }
  return most;
}

}  // namespace oscar::bridge
