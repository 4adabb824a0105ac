#include "oscar/security_files.hpp"

#include <cstdlib>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

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

std::string keystore_from_env() {
  const char* env = std::getenv("OSCAR_KEYSTORE");
  if (!env || !*env) return "";
  return std::filesystem::absolute(env).lexically_normal().string();
}

std::string system_keystore(const YAML::Node& root, const std::string& file) {
  namespace fs = std::filesystem;
  if (auto from_env = keystore_from_env(); !from_env.empty()) return from_env;
  // (A key a map lacks gives an invalid node, whose every query but `if (node)` throws.)
  const auto security = root && root.IsMap() ? root["security"] : YAML::Node();
  const auto keystore = security && security.IsMap() ? security["keystore"] : YAML::Node();
  if (!keystore || !keystore.IsScalar() || keystore.Scalar().empty()) return "";
  fs::path dir = keystore.Scalar();
  if (dir.is_relative()) dir = fs::absolute(file).parent_path() / dir;
  return dir.lexically_normal().string();
}

}  // namespace oscar::security_files
