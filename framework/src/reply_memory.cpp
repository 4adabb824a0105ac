#include "reply_memory.hpp"

#include "oscar/demand.hpp"

namespace oscar::internal {

ReplyMemory::ReplyMemory(std::size_t capacity) : capacity_(capacity) {
  OSCAR_DEMAND(capacity_ > 0, "a reply memory keeps at least one sender");
}

const ConfigReply* ReplyMemory::find(const std::string& sender, std::uint64_t id) {
  const auto it = by_sender_.find(sender);
  if (it == by_sender_.end()) return nullptr;
  recent_.splice(recent_.begin(), recent_, it->second);
  return it->second->reply.id() == id ? &it->second->reply : nullptr;
}

void ReplyMemory::remember(const std::string& sender, const ConfigReply& reply) {
  if (const auto it = by_sender_.find(sender); it != by_sender_.end()) {
    it->second->reply = reply;
    recent_.splice(recent_.begin(), recent_, it->second);
    return;
  }
  if (by_sender_.size() >= capacity_) {
    by_sender_.erase(recent_.back().sender);
    recent_.pop_back();
  }
  recent_.push_front({sender, reply});
  by_sender_.emplace(sender, recent_.begin());
}

}  // namespace oscar::internal
