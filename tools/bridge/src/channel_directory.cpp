#include "channel_directory.hpp"

namespace oscar::bridge {

ChannelDirectory::Change ChannelDirectory::update(
    const std::map<std::string, DdsParticipant::DiscoveredWriter>& writers) {
  Change change;
  for (auto it = live_.begin(); it != live_.end();) {
    if (!it->second.source.empty()) {
      ++it;
      continue;
    }
    const auto w = writers.find(it->first);
    if (w == writers.end() || w->second.alive == 0 || w->second.type != it->second.schema_name) {
      change.removed.push_back(it->second.id);
      it = live_.erase(it);
    } else {
      ++it;
    }
  }
  // A side channel goes with its source.
  for (auto it = live_.begin(); it != live_.end();) {
    if (!it->second.source.empty() && !live_.contains(it->second.source)) {
      change.removed.push_back(it->second.id);
      side_by_source_.erase(it->second.source);
      it = live_.erase(it);
    } else {
      ++it;
    }
  }
  for (const auto& [topic, writer] : writers) {
    if (writer.alive == 0 || !topic.starts_with("oscar/") || live_.contains(topic)) continue;
    auto idl = idl_text_(writer.type);
    if (!idl) {
      if (unknown_.insert(topic).second) change.unknown.push_back(topic);
      continue;
    }
    add({.id = 0, .topic = topic, .schema_name = writer.type, .schema = std::move(*idl)}, change);
    if (!side_channel_) continue;
    for (auto& side : side_channel_(topic, writer.type)) {
      const auto side_topic = side.topic;
      add(std::move(side), change);
      side_by_source_[topic].push_back(live_.at(side_topic).id);
    }
  }
  return change;
}

// Advertises `channel` with the id its topic had, if it had the same schema; else a new one.
void ChannelDirectory::add(ChannelInfo channel, Change& change) {
  auto& known = known_[channel.topic];
  if (known.id == 0 || known.schema_name != channel.schema_name) {
    known = std::move(channel);
    known.id = next_id_++;
  }
  live_[known.topic] = known;
  change.added.push_back(known);
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

std::vector<std::uint32_t> ChannelDirectory::sides_of(const std::string& source) const {
  const auto it = side_by_source_.find(source);
  return it == side_by_source_.end() ? std::vector<std::uint32_t>{} : it->second;
}

}  // namespace oscar::bridge
