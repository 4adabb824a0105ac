#pragma once
/// @file Where an identity's DDS Security files lie in an OSCAR keystore (docs/security.md) and
/// the Fast DDS properties that load them. `oscar security init` writes this layout; a process
/// that runs as an identity passes these properties to its participant.

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace YAML {
class Node;
}

namespace oscar::security_files {

/// The files of one identity's folder, each named after what it is.
inline constexpr const char* kIdentityCa = "identity_ca.cert.pem";
inline constexpr const char* kCertificate = "cert.pem";
inline constexpr const char* kPrivateKey = "key.pem";
inline constexpr const char* kPermissionsCa = "permissions_ca.cert.pem";
inline constexpr const char* kGovernance = "governance.p7s";
inline constexpr const char* kPermissions = "permissions.p7s";

/// The identities a process may run as besides modules and monitors.
inline constexpr const char* kRegistry = "registry";
inline constexpr const char* kBoot = "boot";
inline constexpr const char* kOperator = "operator";           ///< the tools, read-only
inline constexpr const char* kOperatorBoot = "operator_boot";  ///< the tools, with boot's rights

/// "module.<name>": a module's identity (the coordinator's is "module.coordinator").
std::string module_identity(std::string_view module);
/// "monitor.<host>": the identity of a host's monitor.
std::string monitor_identity(std::string_view host);

/// "<keystore>/identities/<identity>".
std::filesystem::path identity_dir(const std::filesystem::path& keystore,
                                   std::string_view identity);

/// A Fast DDS property: name and value.
using Property = std::pair<std::string, std::string>;

/// The participant properties that make Fast DDS authenticate as `identity` with the builtin
/// PKI-DH plugin, enforce its permissions (Access-Permissions) and protect traffic as the
/// governance says (AES-GCM-GMAC); files are given as absolute "file://" URIs.
/// @throws std::invalid_argument naming the missing file if the identity's folder lacks one
///         (run `oscar security init`).
std::vector<Property> dds_security_properties(const std::filesystem::path& keystore,
                                              std::string_view identity);

/// $OSCAR_KEYSTORE as an absolute folder (`oscar boot --keystore` sets it for every process it
/// starts), or "" if unset.
std::string keystore_from_env();

/// The keystore the processes of the system in `file` (whose YAML is `root`) run with:
/// $OSCAR_KEYSTORE if set (`oscar boot --keystore` sets it for every process it starts), else
/// the file's `security: keystore:` (a relative folder taken from the file's folder), else ""
/// (the system runs without DDS Security).
std::string system_keystore(const YAML::Node& root, const std::string& file);

}  // namespace oscar::security_files
