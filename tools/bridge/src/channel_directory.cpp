#include "channel_directory.hpp"

namespace oscar::bridge {

ChannelDirectory::Change ChannelDirectory::update(
    const std::map<std::string, DdsParticipant::DiscoveredWriter>& writers) {
  Change change;
  for (auto it = live_.begin(); it != live_.end();) {
    const auto w = writers.find(it->first);
    if (w == writers.end() || w->second.alive == 0 || w->second.type != it->second.schema_name) {
      change.removed.push_back(it->second.id);
      it = live_.erase(it);
    } else {
      ++it;
    }
  }
  for (const auto& [topic, writer] : writers) {
    if (writer.alive == 0 || !topic.starts_with("oscar/") || live_.contains(topic)) continue;
    const auto idl = idl_texts_.find(writer.type);
    if (idl == idl_texts_.end()) {
      if (unknown_.insert(topic).second) change.unknown.push_back(topic);
      continue;
    }
    auto& known = known_[topic];
    if (known.schema_name != writer.type) known = {next_id_++, topic, writer.type, idl->second};
    live_[topic] = known;
    change.added.push_back(known);
  }
  return change;
}

std::vector<ChannelInfo> ChannelDirectory::channels() const {
  std::vector<ChannelInfo> out;
  for (const auto& [topic, c] : live_) out.push_back(c);
  return out;
}

const ChannelInfo* ChannelDirectory::find(std::uint32_t id) const {
  for (const auto& [topic, c] : live_) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

std::optional<std::uint32_t> ChannelDirectory::id_of(const std::string& topic) const {
  const auto it = live_.find(topic);
  return it == live_.end() ? std::nullopt : std::optional(it->second.id);
}

}  // namespace oscar::bridge
