#pragma once
// An OSCAR keystore (docs/security.md): two CAs, and per identity of a system a key, a
// certificate and signed permissions, laid out so that each identity's folder holds exactly the
// files its DDS Security properties name (oscar/security_files.hpp).
//
//   DIR/private/{identity_ca,permissions_ca}.key.pem     the CAs' keys (0600)
//   DIR/public/{identity_ca,permissions_ca}.cert.pem     the CAs' certificates
//   DIR/public/governance.{xml,p7s}                      the system's rules, signed
//   DIR/identities/<identity>/cert.pem, key.pem (0600), permissions.{xml,p7s},
//       identity_ca.cert.pem, permissions_ca.cert.pem, governance.p7s  (links into public/)

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "identity_policy.hpp"
#include "oscar/registry/system_spec.hpp"

namespace oscar::security {

struct KeystoreSettings {
  std::chrono::hours ca_validity{24 * 3650};       ///< about 10 years
  std::chrono::hours identity_validity{24 * 730};  ///< about 2 years
  /// init renews a certificate (same key) and check warns this long before it expires.
  std::chrono::hours renew_before{24 * 30};
};

/// Creates or brings up to date the keystore of `system` in `dir`: keeps existing CAs and keys,
/// adds identities the system has gained, renews certificates about to expire, rewrites and
/// re-signs governance and permissions that no longer match the system file. Identities the
/// system no longer has are left in place (and reported).
/// @returns one line per thing done or kept, for the user.
/// @throws std::runtime_error if `dir` is a non-empty folder without identities/ (not a
///         keystore), if a CA has a certificate without its key or the reverse (a new CA would
///         orphan every identity), or if a file cannot be written.
std::vector<std::string> init_keystore(const SystemSpec& system, const std::filesystem::path& dir,
                                       const KeystoreSettings& settings = {});

struct Finding {
  enum class Level { kWarning, kError };
  Level level;
  std::string text;
};

/// Everything wrong with `dir` as the keystore of `system` at time `now`: missing or extra
/// identities, certificates not issued by the identity CA or expired (warnings within
/// `settings.renew_before`), keys not matching or readable by others, documents not signed by
/// the permissions CA or no longer what the system file gives. Empty when all is well.
std::vector<Finding> check_keystore(
    const SystemSpec& system, const std::filesystem::path& dir,
    std::chrono::system_clock::time_point now = std::chrono::system_clock::now(),
    const KeystoreSettings& settings = {});

/// One identity as its keystore folder shows it (its signed permissions, not the system file).
struct IdentityListing {
  std::string name;
  std::string subject;
  std::chrono::system_clock::time_point not_after;
  std::vector<std::string> publish;  ///< from its permissions document
  std::string problem;               ///< why a field could not be read, else empty
};

/// Every identity folder of `dir`, sorted by name.
/// @throws std::runtime_error if `dir` has no identities/ folder.
std::vector<IdentityListing> list_keystore(const std::filesystem::path& dir);

}  // namespace oscar::security
