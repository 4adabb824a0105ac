#pragma once
// The applet protocol's vocabulary on the wire (oscar/sched/..., not installed): notification
// kinds as text, and a fresh random number for sessions and coordinator starts.

#include <cstdint>
#include <optional>
#include <string>

#include "oscar/applets/scheduler.hpp"

namespace oscar::coordinator::internal {

/// "granted", "revoke_requested", ... (SchedNotice.kind).
const char* notice_kind(applets::Notification::Kind kind);
/// The kind a text names, if it names one of the scheduler's.
std::optional<applets::Notification::Kind> notice_kind(const std::string& text);
/// Whether a notification is about taking a bundle away (seed footnote 11).
bool is_revocation(applets::Notification::Kind kind);
/// The operator's events an applet takes (AppletEvent.event), for messages: "request, ...".
inline constexpr const char* kAppletEvents =
    "request, release, trigger, yield, set_priority, set_deadline, negotiate, crash, add, remove";
/// Whether `event` is one of kAppletEvents.
bool known_applet_event(const std::string& event);
/// A random number, never 0 (a session, a start of the coordinator).
std::uint64_t fresh_id();

}  // namespace oscar::coordinator::internal
