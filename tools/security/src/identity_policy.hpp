#pragma once
// Who may publish what (docs/security.md, "What each identity may do"): the identities of a
// system and their topics, derived from its system file alone, so the permissions follow the
// graph without loading any kernel plugin.

#include <string>
#include <vector>

#include "oscar/registry/system_spec.hpp"

namespace oscar::security {

struct IdentityPolicy {
  std::string name;  ///< e.g. "module.camera" (security_files.hpp)
  /// Topic names or fnmatch patterns it may create writers on (DDS Security <publish>).
  std::vector<std::string> publish;
  /// Topic patterns it may read. Reading is not access-controlled (the governance leaves
  /// read_access_control off: tools and loggers read any topic), so this is "*" for all.
  std::vector<std::string> subscribe;
};

/// Every identity of `system`: registry, boot, operator, operator_boot, one monitor per host and
/// one per module (the coordinator's and the applet processes' included), in that order.
std::vector<IdentityPolicy> identities_of(const SystemSpec& system);

}  // namespace oscar::security
