#include "command_bounds.hpp"

#include <fmt/format.h>

namespace oscar::internal {

const char* command_kind_name(CommandKind kind) {
  switch (kind) {
    case CMD_ACTIVATE:
      return "activate";
    case CMD_DEACTIVATE:
      return "deactivate";
    case CMD_TRIGGER:
      return "trigger";
    case CMD_SET_CYCLE:
      return "set_cycle";
    case CMD_SET_PARAM:
      return "set_param";
    case CMD_REWIRE:
      return "rewire";
    case CMD_SUSPEND:
      return "suspend";
    case CMD_RESUME:
      return "resume";
    case CMD_STUB:
      return "stub";
    case CMD_SHUTDOWN:
      return "shutdown";
    case CMD_COMMAND:
      return "command";
  }
  return nullptr;
}

std::optional<std::string> malformed(const ConfigCommand& c) {
  const auto too_long = [](std::string_view field, std::string_view value, std::size_t limit) {
    return fmt::format("refused: {} is {} bytes long ('{}'), over the limit of {}", field,
                       value.size(), excerpt(value), limit);
  };
  if (c.sender().size() > kMaxSenderChars) {
    return too_long("sender", c.sender(), kMaxSenderChars);
  }
  if (!command_kind_name(c.kind())) {
    return fmt::format(
        "refused: kind {} is no CommandKind (known: 0 activate to {} command, as in "
        "idl/oscar/config.idl)",
        static_cast<long long>(c.kind()), static_cast<int>(CMD_COMMAND));
  }
  if (c.args().size() > kMaxArgs) {
    return fmt::format("refused: {} arguments, over the limit of {}", c.args().size(), kMaxArgs);
  }
  for (std::size_t i = 0; i < c.args().size(); ++i) {
    if (c.args()[i].size() > kMaxArgChars) {
      return too_long(fmt::format("argument {}", i + 1).c_str(), c.args()[i], kMaxArgChars);
    }
  }
  if (c.payload_type().size() > kMaxPayloadTypeChars) {
    return too_long("payload_type", c.payload_type(), kMaxPayloadTypeChars);
  }
  if (c.payload().size() > kMaxPayloadBytes) {
    return fmt::format("refused: payload is {} bytes, over the limit of {}", c.payload().size(),
                       kMaxPayloadBytes);
  }
  return std::nullopt;
}

std::string excerpt(std::string_view text, std::size_t max_chars) {
  if (text.size() <= max_chars) return std::string(text);
  std::size_t cut = max_chars;
  // Back off continuation bytes (10xxxxxx) so that the cut is between characters.
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  return fmt::format("{}... ({} more bytes)", text.substr(0, cut), text.size() - cut);
}

}  // namespace oscar::internal
