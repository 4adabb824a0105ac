#include "sched_wire.hpp"

#include <unistd.h>

#include <array>
#include <chrono>
#include <random>
#include <utility>

namespace oscar::coordinator::internal {
namespace {

using Kind = applets::Notification::Kind;
constexpr std::array<std::pair<Kind, const char*>, 7> kKinds{{
    {Kind::kGranted, "granted"},
    {Kind::kRevokeRequested, "revoke_requested"},
    {Kind::kNegotiationAccepted, "negotiation_accepted"},
    {Kind::kNegotiationRejected, "negotiation_rejected"},
    {Kind::kRevokedByForce, "revoked_by_force"},
    {Kind::kDeadlineOverlap, "deadline_overlap"},
    {Kind::kDeadlineExpired, "deadline_expired"},
}};

}  // namespace

const char* notice_kind(Kind kind) {
  for (const auto& [k, text] : kKinds) {
    if (k == kind) return text;
  }
  return "unknown";
}

std::optional<Kind> notice_kind(const std::string& text) {
  for (const auto& [k, t] : kKinds) {
    if (text == t) return k;
  }
  return std::nullopt;
}

bool is_revocation(Kind kind) {
  return kind == Kind::kRevokeRequested || kind == Kind::kNegotiationAccepted ||
         kind == Kind::kNegotiationRejected || kind == Kind::kRevokedByForce;
}

bool known_applet_event(const std::string& event) {
  for (const char* e : {"request", "release", "trigger", "yield", "set_priority", "set_deadline",
                        "negotiate", "crash"}) {
    if (event == e) return true;
  }
  return false;
}

std::uint64_t fresh_id() {
  std::random_device device;
  std::mt19937_64 gen(
      (static_cast<std::uint64_t>(device()) << 32) ^ device() ^
      static_cast<std::uint64_t>(getpid()) ^
      static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
  std::uint64_t id = 0;
  while (id == 0) id = gen();
  return id;
}

}  // namespace oscar::coordinator::internal
