#pragma once
// Internal: the limits a configuration command must keep before a module acts on it or quotes
// it (docs/architecture.md, "Configuration"). A command is a sample anyone on the domain may
// write: its strings are as long and its kind as strange as the writer likes. What a module
// keeps or repeats (its repeat-answer memory, replies, log lines) is made only of commands that
// keep these limits, and of bounded excerpts of those that do not.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include <oscar/config.h>

namespace oscar::internal {

/// The longest `sender` a module accepts (and remembers a reply for).
inline constexpr std::size_t kMaxSenderChars = 64;
/// The most arguments a command carries (rewire takes 4, the most of any kind).
inline constexpr std::size_t kMaxArgs = 8;
/// The longest argument (a parameter value, a mode, a source).
inline constexpr std::size_t kMaxArgChars = 4096;
/// The longest `payload_type` (an IDL type name).
inline constexpr std::size_t kMaxPayloadTypeChars = 256;
/// The largest CMD_COMMAND payload (a kernel's CDR-encoded request).
inline constexpr std::size_t kMaxPayloadBytes = 1024 * 1024;
/// The longest text (error, note, answer) a reply carries.
inline constexpr std::size_t kMaxReplyTextChars = 4096;
/// How much of an over-long or unknown field a refusal quotes.
inline constexpr std::size_t kQuoteChars = 40;

/// The name of a known kind ("activate", ...), or nullptr for a value outside CommandKind.
const char* command_kind_name(CommandKind kind);

/// Why `command` breaks a limit above or has a kind outside CommandKind, naming the field, the
/// value (an excerpt) and the rule; nullopt if it keeps them all.
std::optional<std::string> malformed(const ConfigCommand& command);

/// `text` if it has at most `max_chars` characters, else its first `max_chars` followed by
/// "... (N more bytes)". Never splits a UTF-8 sequence.
std::string excerpt(std::string_view text, std::size_t max_chars = kQuoteChars);

}  // namespace oscar::internal
