#pragma once
// ChannelDirectory: the bridge's channels, one per topic of the running system that a writer
// publishes now and whose type has an IDL text (OSCAR's own, or one its module announced); updated
// from what discovery shows, so a topic that appears is advertised and one whose last writer went
// is unadvertised. A topic may have side channels too (side_channels.hpp): they come and go with
// their source.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "foxglove_protocol.hpp"
#include "oscar/dds_participant.hpp"

namespace oscar::bridge {

class ChannelDirectory {
 public:
  /// The side channels of a topic of a type, if it has any (side_channels_for()).
  using SideChannelFn =
      std::function<std::vector<ChannelInfo>(const std::string& topic, const std::string& type)>;

  /// The self-contained IDL text of a type by scoped name, or nullopt if there is none (yet).
  using IdlTextFn = std::function<std::optional<std::string>(const std::string& type)>;

  /// `idl_text`: OSCAR's own texts and those modules announce (AnnouncedTypes::idl_text);
  /// `side_channel`: none if empty.
  explicit ChannelDirectory(IdlTextFn idl_text, SideChannelFn side_channel = {})
      : idl_text_(std::move(idl_text)), side_channel_(std::move(side_channel)) {}

  struct Change {
    std::vector<ChannelInfo> added;
    std::vector<std::uint32_t> removed;
    /// Topics seen for the first time whose type has no IDL text here (not advertised until a
    /// text for it turns up: each update() looks again).
    std::vector<std::string> unknown;
  };
  /// Compares the writers discovery shows now with the channels so far. A topic that comes
  /// back with its old type gets its old channel id; with another type, a new one.
  Change update(const std::map<std::string, DdsParticipant::DiscoveredWriter>& writers);

  /// The channels advertised now.
  std::vector<ChannelInfo> channels() const;
  /// The channel advertised now with that id.
  const ChannelInfo* find(std::uint32_t id) const;
  /// The id of the channel advertised now for `topic`.
  std::optional<std::uint32_t> id_of(const std::string& topic) const;
  /// The ids of the side channels advertised now for the DDS topic `source` (none if none).
  std::vector<std::uint32_t> sides_of(const std::string& source) const;

 private:
  void add(ChannelInfo channel, Change& change);

  IdlTextFn idl_text_;
  SideChannelFn side_channel_;
  std::map<std::string, ChannelInfo> live_;   // by topic
  std::map<std::string, ChannelInfo> known_;  // every channel ever made, by topic
  std::map<std::string, std::vector<std::uint32_t>> side_by_source_;  // live side channels
  std::set<std::string> unknown_;  // topics reported as having no IDL
  std::uint32_t next_id_ = 1;
};

}  // namespace oscar::bridge
