#pragma once
// Where things lie in a keystore (keystore.hpp) and what init, check and list share: the files,
// their reading and writing, dates as the documents write them, the permissions an identity's
// certificate calls for.

#include <chrono>
#include <filesystem>
#include <optional>
#include <set>
#include <string>

#include "identity_policy.hpp"
#include "pki.hpp"

namespace oscar::security::layout {

using Clock = std::chrono::system_clock;

inline constexpr const char* kIdentityCaName = "identity_ca";
inline constexpr const char* kPermissionsCaName = "permissions_ca";
inline constexpr const char* kPermissionsXml = "permissions.xml";

std::filesystem::path ca_key_file(const std::filesystem::path& dir, const char* ca);
std::filesystem::path ca_cert_file(const std::filesystem::path& dir, const char* ca);
std::filesystem::path governance_xml_file(const std::filesystem::path& dir);
std::filesystem::path governance_file(const std::filesystem::path& dir);
/// The names of the folders under DIR/identities.
std::set<std::string> identity_folders(const std::filesystem::path& dir);

std::optional<std::string> read_text(const std::filesystem::path& file);
/// @throws std::runtime_error naming the file.
void write_text(const std::filesystem::path& file, const std::string& text);
/// Creates `dir` if needed and makes it owner-only (0700).
void make_private_dir(const std::filesystem::path& dir);
/// True if its mode lets the group or others in.
bool others_may_read(const std::filesystem::path& path);

/// "YYYY-MM-DDTHH:MM:SS" (UTC), as the permissions' validity is written.
std::string timestamp(Clock::time_point t);
/// "YYYY-MM-DD" (UTC).
std::string date(Clock::time_point t);
long days_between(Clock::time_point from, Clock::time_point to);

/// The cue protection `system` asks for (none without a security: section).
SecuritySpec::CueProtection cue_protection_of(const SystemSpec& system);
/// The permissions document `identity` needs with certificate `cert`.
std::string expected_permissions(const IdentityPolicy& identity, const X509& cert);
/// True if `signed_file` is `text` signed by (a certificate of) `ca`.
bool signed_as(const std::filesystem::path& signed_file, const std::string& text, const X509& ca);

}  // namespace oscar::security::layout
