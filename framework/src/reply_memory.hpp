#pragma once
// Internal: a module's repeat-answer memory. A client that did not see its reply sends the same
// command again (same sender, same id); the module answers it with the reply it gave, instead of
// applying it twice. Only the last reply per sender is needed, and only for the senders heard
// from most recently: anyone may write commands under any number of names, so the memory keeps
// the `capacity` senders used last and forgets the one unused longest.

#include <cstddef>
#include <cstdint>
#include <list>
#include <string>
#include <unordered_map>

#include <oscar/config.h>

namespace oscar::internal {

class ReplyMemory {
 public:
  /// The senders a module remembers a reply for (boot, the registry, the coordinator and a few
  /// operators' tools need far fewer).
  static constexpr std::size_t kDefaultCapacity = 32;

  explicit ReplyMemory(std::size_t capacity = kDefaultCapacity);

  /// The reply given to `sender`'s command `id`, if it was the last one of that sender and is
  /// still remembered; marks the sender as used.
  const ConfigReply* find(const std::string& sender, std::uint64_t id);
  /// Remembers `reply` as `sender`'s last, forgetting the sender unused longest if full.
  void remember(const std::string& sender, const ConfigReply& reply);
  std::size_t size() const { return by_sender_.size(); }

 private:
  struct Entry {
    std::string sender;
    ConfigReply reply;
  };
  std::size_t capacity_;
  std::list<Entry> recent_;  // used last first
  std::unordered_map<std::string, std::list<Entry>::iterator> by_sender_;
};

}  // namespace oscar::internal
