#include "keystore_layout.hpp"

#include <sys/stat.h>

#include <ctime>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "oscar/security_files.hpp"
#include "policy_xml.hpp"

namespace oscar::security::layout {

namespace fs = std::filesystem;
namespace files = security_files;

fs::path ca_key_file(const fs::path& dir, const char* ca) {
  return dir / "private" / fmt::format("{}.key.pem", ca);
}
fs::path ca_cert_file(const fs::path& dir, const char* ca) {
  return dir / "public" / fmt::format("{}.cert.pem", ca);
}
fs::path governance_xml_file(const fs::path& dir) { return dir / "public" / "governance.xml"; }
fs::path governance_file(const fs::path& dir) { return dir / "public" / files::kGovernance; }

std::optional<std::string> read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

// A folder only its owner may enter: the keystore holds private keys.
void make_private_dir(const fs::path& dir) {
  fs::create_directories(dir);
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace);
}

bool others_may_read(const fs::path& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && (st.st_mode & 077) != 0;
}

std::string timestamp(Clock::time_point t) {
  const std::time_t tt = Clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

std::string date(Clock::time_point t) { return timestamp(t).substr(0, 10); }

long days_between(Clock::time_point from, Clock::time_point to) {
  return static_cast<long>(std::chrono::duration_cast<std::chrono::hours>(to - from).count() / 24);
}

// The grant is valid as long as the certificate, but from a day earlier: Fast DDS reads these
// dates as local time (mktime), so east of UTC a grant dated from the certificate's first second
// would not be valid yet for hours. The certificate's own dates still bound authentication.
std::string expected_permissions(const IdentityPolicy& identity, const X509& cert) {
  return permissions_xml(identity, pki::subject(cert),
                         timestamp(pki::not_before(cert) - std::chrono::hours(24)),
                         timestamp(pki::not_after(cert)));
}

// True if `signed_file` is `text` signed by `ca`.
bool signed_as(const fs::path& signed_file, const std::string& text, const X509& ca) {
  const auto smime = read_text(signed_file);
  std::string error;
  return smime && pki::verify_smime(*smime, ca, error) == text;
}

SecuritySpec::CueProtection cue_protection_of(const SystemSpec& system) {
  return system.security ? system.security->cue_protection : SecuritySpec::CueProtection::kNone;
}

std::set<std::string> identity_folders(const fs::path& dir) {
  std::set<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir / "identities", ec)) {
    if (e.is_directory()) names.insert(e.path().filename().string());
  }
  return names;
}

}  // namespace oscar::security::layout
