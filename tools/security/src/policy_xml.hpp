#pragma once
// The DDS Security governance and permissions documents (OMG DDS Security 1.1 §9.4), in the
// element order Fast DDS 2.9's parsers demand.

#include <string>

#include "identity_policy.hpp"
#include "oscar/registry/system_spec.hpp"

namespace oscar::security {

/// The system-wide rules: no unauthenticated participants, discovery and liveliness encrypted,
/// write access control on every topic; cue and pull topics protected as `cue` says (none;
/// sign: submessages signed; encrypt: submessages and data encrypted), every other (control)
/// topic with submessages signed and data encrypted.
std::string governance_xml(SecuritySpec::CueProtection cue);

/// What `identity` may do, for the holder of the certificate with subject `subject_rfc2253`,
/// valid like its certificate ("YYYY-MM-DDTHH:MM:SS", UTC). Anything not allowed is denied.
std::string permissions_xml(const IdentityPolicy& identity, const std::string& subject_rfc2253,
                            const std::string& not_before, const std::string& not_after);

}  // namespace oscar::security
