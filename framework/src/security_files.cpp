#include "oscar/security_files.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace oscar::security_files {

std::string module_identity(std::string_view module) { return fmt::format("module.{}", module); }

std::string monitor_identity(std::string_view host) { return fmt::format("monitor.{}", host); }

std::filesystem::path identity_dir(const std::filesystem::path& keystore,
                                   std::string_view identity) {
  return keystore / "identities" / std::string(identity);
}

std::vector<Property> dds_security_properties(const std::filesystem::path& keystore,
                                              std::string_view identity) {
  const auto dir = std::filesystem::absolute(identity_dir(keystore, identity));
  // Checked here rather than left to Fast DDS, which reports a missing file only as a failed
  // participant creation without naming it.
  const auto uri = [&](const char* file) {
    const auto path = dir / file;
    if (!std::filesystem::is_regular_file(path)) {
      throw std::invalid_argument(
          fmt::format("keystore {}: identity '{}' has no {} (run `oscar security init`)",
                      keystore.string(), identity, path.string()));
    }
    return "file://" + path.string();  // Fast DDS takes file:// URIs only
  };
  const std::string auth = "dds.sec.auth.builtin.PKI-DH.";
  const std::string access = "dds.sec.access.builtin.Access-Permissions.";
  return {
      {"dds.sec.auth.plugin", "builtin.PKI-DH"},
      {auth + "identity_ca", uri(kIdentityCa)},
      {auth + "identity_certificate", uri(kCertificate)},
      {auth + "private_key", uri(kPrivateKey)},
      {"dds.sec.access.plugin", "builtin.Access-Permissions"},
      {access + "permissions_ca", uri(kPermissionsCa)},
      {access + "governance", uri(kGovernance)},
      {access + "permissions", uri(kPermissions)},
      {"dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC"},
  };
}

}  // namespace oscar::security_files
