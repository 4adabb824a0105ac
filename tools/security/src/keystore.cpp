#include "keystore.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <ctime>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "oscar/security_files.hpp"
#include "pki.hpp"
#include "policy_xml.hpp"

namespace oscar::security {
namespace {

namespace fs = std::filesystem;
namespace files = security_files;
using Clock = std::chrono::system_clock;

constexpr const char* kIdentityCaName = "identity_ca";
constexpr const char* kPermissionsCaName = "permissions_ca";
constexpr const char* kPermissionsXml = "permissions.xml";

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

struct Ca {
  pki::Cert cert;
  pki::Key key;
};

Ca open_or_create_ca(const fs::path& dir, const char* name, const KeystoreSettings& settings,
                     std::vector<std::string>& said) {
  const auto key_file = ca_key_file(dir, name);
  const auto cert_file = ca_cert_file(dir, name);
  const bool has_key = fs::exists(key_file);
  const bool has_cert = fs::exists(cert_file);
  if (has_key && has_cert) {
    Ca ca{pki::read_cert(cert_file), pki::read_key(key_file)};
    if (!pki::key_matches(*ca.cert, *ca.key)) {
      throw std::runtime_error(
          fmt::format("{} is not the key of {}", key_file.string(), cert_file.string()));
    }
    said.push_back(fmt::format("kept {} ({}, until {})", name, pki::subject(*ca.cert),
                               date(pki::not_after(*ca.cert))));
    return ca;
  }
  if (has_key || has_cert) {
    throw std::runtime_error(fmt::format(
        "{} has {} but not {}: restore it (a new CA would invalidate every identity), or delete "
        "the keystore and run init again",
        dir.string(), (has_key ? key_file : cert_file).string(),
        (has_key ? cert_file : key_file).string()));
  }
  auto key = pki::new_key();
  const std::string cn = std::string("OSCAR ") +
                         (name == std::string(kIdentityCaName) ? "identity CA" : "permissions CA");
  auto cert = pki::issue(*key, cn, nullptr, *key, settings.ca_validity, true);
  pki::write_key(key_file, *key);
  pki::write_cert(cert_file, *cert);
  said.push_back(fmt::format("created {} ({}, until {})", name, pki::subject(*cert),
                             date(pki::not_after(*cert))));
  return {std::move(cert), std::move(key)};
}

// Points `link` at `target` (relative), replacing whatever is there.
void ensure_link(const fs::path& link, const fs::path& target) {
  std::error_code ec;
  if (fs::is_symlink(link) && fs::read_symlink(link, ec) == target) return;
  fs::remove(link);
  fs::create_symlink(target, link);
}

// Brings one identity's folder up to date; returns what it did ("" when nothing changed).
std::string init_identity(const fs::path& dir, const IdentityPolicy& identity, const Ca& id_ca,
                          const Ca& perm_ca, const KeystoreSettings& settings) {
  const auto idir = files::identity_dir(dir, identity.name);
  const bool existed = fs::exists(idir);
  make_private_dir(idir);
  const auto key_file = idir / files::kPrivateKey;
  const auto cert_file = idir / files::kCertificate;
  std::vector<std::string> done;

  pki::Key key;
  if (fs::exists(key_file)) {
    key = pki::read_key(key_file);
    if (others_may_read(key_file)) {
      fs::permissions(key_file, fs::perms::owner_read | fs::perms::owner_write,
                      fs::perm_options::replace);
      done.push_back("made its key readable by its owner only");
    }
  } else {
    key = pki::new_key();
    pki::write_key(key_file, *key);
    if (existed) done.push_back("new key");
  }
  pki::Cert cert;
  std::string reissue = "new certificate";
  if (fs::exists(cert_file)) {
    cert = pki::read_cert(cert_file);
    if (const auto why = pki::not_issued_by(*cert, *id_ca.cert)) {
      reissue = fmt::format("new certificate (the old one: {})", *why);
      cert.reset();
    } else if (!pki::key_matches(*cert, *key)) {
      reissue = "new certificate (the old one was not of its key)";
      cert.reset();
    } else if (pki::not_after(*cert) - Clock::now() < settings.renew_before) {
      reissue = fmt::format("renewed its certificate (it expires {})", date(pki::not_after(*cert)));
      cert.reset();
    }
  }
  if (!cert) {
    cert = pki::issue(*key, identity.name, id_ca.cert.get(), *id_ca.key, settings.identity_validity,
                      false);
    pki::write_cert(cert_file, *cert);
    if (existed) done.push_back(reissue);
  }
  // The shared files, linked so that each identity's folder is complete for Fast DDS.
  ensure_link(idir / files::kIdentityCa, fs::path("../../public") / files::kIdentityCa);
  ensure_link(idir / files::kPermissionsCa, fs::path("../../public") / files::kPermissionsCa);
  ensure_link(idir / files::kGovernance, fs::path("../../public") / files::kGovernance);

  const auto xml = expected_permissions(identity, *cert);
  const auto signed_file = idir / files::kPermissions;
  if (read_text(idir / kPermissionsXml) != xml || !signed_as(signed_file, xml, *perm_ca.cert)) {
    write_text(idir / kPermissionsXml, xml);
    write_text(signed_file, pki::sign_smime(xml, *perm_ca.cert, *perm_ca.key));
    if (existed) done.push_back("rewrote its permissions");
  }
  if (!existed) {
    return fmt::format("created identity {} ({}, until {})", identity.name, pki::subject(*cert),
                       date(pki::not_after(*cert)));
  }
  if (done.empty()) return "";
  std::string line = "updated identity " + identity.name + ": ";
  for (std::size_t i = 0; i < done.size(); ++i) line += (i ? ", " : "") + done[i];
  return line;
}

std::set<std::string> identity_folders(const fs::path& dir) {
  std::set<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir / "identities", ec)) {
    if (e.is_directory()) names.insert(e.path().filename().string());
  }
  return names;
}

std::string unescaped(std::string text) {
  for (const auto& [from, to] : std::initializer_list<std::pair<std::string, std::string>>{
           {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&amp;", "&"}}) {
    for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + 1)) {
      text.replace(at, from.size(), to);
    }
  }
  return text;
}

// The <topic>s of the <publish> element of a permissions document.
std::vector<std::string> published_topics(const std::string& xml) {
  std::vector<std::string> topics;
  const auto begin = xml.find("<publish>");
  const auto end = xml.find("</publish>");
  if (begin == std::string::npos || end == std::string::npos) return topics;
  const std::string open = "<topic>", close = "</topic>";
  for (auto at = xml.find(open, begin); at != std::string::npos && at < end;
       at = xml.find(open, at + 1)) {
    const auto stop = xml.find(close, at);
    topics.push_back(unescaped(xml.substr(at + open.size(), stop - at - open.size())));
  }
  return topics;
}

class Checker {
 public:
  Checker(const fs::path& dir, Clock::time_point now, const KeystoreSettings& settings)
      : dir_(dir), now_(now), settings_(settings) {}

  void error(std::string text) { found_.push_back({Finding::Level::kError, std::move(text)}); }
  void warning(std::string text) { found_.push_back({Finding::Level::kWarning, std::move(text)}); }

  void dates(const std::string& what, const X509& cert) {
    const auto until = pki::not_after(cert);
    if (until <= now_) {
      error(fmt::format("{}: certificate expired on {}", what, date(until)));
    } else if (until - now_ < settings_.renew_before) {
      warning(
          fmt::format("{}: certificate expires in {} days ({}); `oscar security init` renews it",
                      what, days_between(now_, until), date(until)));
    } else if (pki::not_before(cert) > now_) {
      error(fmt::format("{}: certificate not valid before {}", what,
                        timestamp(pki::not_before(cert))));
    }
  }

  // A CA's certificate, checked as self-signed and in date; null if it cannot be used.
  pki::Cert ca(const char* name) {
    const auto file = ca_cert_file(dir_, name);
    pki::Cert cert;
    try {
      cert = pki::read_cert(file);
    } catch (const std::exception& e) {
      error(fmt::format("{}: {}", name, e.what()));
      return nullptr;
    }
    if (const auto why = pki::not_issued_by(*cert, *cert)) {
      error(fmt::format("{}: {} is not a valid self-signed CA certificate: {}", name, file.string(),
                        *why));
      return nullptr;
    }
    dates(name, *cert);
    if (!fs::exists(ca_key_file(dir_, name))) {
      warning(fmt::format("{}: no private key in {} (init cannot add or renew identities here)",
                          name, (dir_ / "private").string()));
    }
    return cert;
  }

  void identity(const IdentityPolicy& policy, const X509* id_ca, const X509* perm_ca) {
    const auto idir = files::identity_dir(dir_, policy.name);
    const auto& name = policy.name;
    if (!fs::is_directory(idir)) {
      error(fmt::format("{}: missing (the system file has it; run `oscar security init`)", name));
      return;
    }
    for (const auto* shared : {files::kIdentityCa, files::kPermissionsCa, files::kGovernance}) {
      if (!fs::is_regular_file(idir / shared)) {
        error(fmt::format("{}: {} is missing or a broken link", name, (idir / shared).string()));
      }
    }
    pki::Cert cert;
    try {
      cert = pki::read_cert(idir / files::kCertificate);
    } catch (const std::exception& e) {
      error(fmt::format("{}: {}", name, e.what()));
      return;
    }
    if (id_ca) {
      if (const auto why = pki::not_issued_by(*cert, *id_ca)) {
        error(fmt::format("{}: certificate not issued by the identity CA: {}", name, *why));
      }
    }
    dates(name, *cert);
    const auto key_file = idir / files::kPrivateKey;
    try {
      if (!pki::key_matches(*cert, *pki::read_key(key_file))) {
        error(fmt::format("{}: {} is not the key of its certificate", name, key_file.string()));
      }
      if (others_may_read(key_file)) {
        error(fmt::format("{}: {} is readable by others (chmod 600)", name, key_file.string()));
      }
    } catch (const std::exception& e) {
      error(fmt::format("{}: {}", name, e.what()));
    }
    if (!perm_ca) return;
    const auto smime = read_text(idir / files::kPermissions);
    std::string why;
    const auto text = smime ? pki::verify_smime(*smime, *perm_ca, why) : std::nullopt;
    if (!smime) {
      error(fmt::format("{}: no {}", name, (idir / files::kPermissions).string()));
    } else if (!text) {
      error(fmt::format("{}: permissions not signed by the permissions CA: {}", name, why));
    } else if (*text != expected_permissions(policy, *cert)) {
      error(
          fmt::format("{}: permissions differ from what the system file gives (run `oscar "
                      "security init`)",
                      name));
    }
  }

  std::vector<Finding> found_;

 private:
  fs::path dir_;
  Clock::time_point now_;
  KeystoreSettings settings_;
};

}  // namespace

std::vector<std::string> init_keystore(const SystemSpec& system, const fs::path& dir,
                                       const KeystoreSettings& settings) {
  std::vector<std::string> said;
  const bool existed = fs::exists(dir);
  if (existed && others_may_read(dir))
    said.push_back("made " + dir.string() + " owner-only (0700)");
  make_private_dir(dir);
  make_private_dir(dir / "private");
  fs::create_directories(dir / "public");
  make_private_dir(dir / "identities");
  const auto id_ca = open_or_create_ca(dir, kIdentityCaName, settings, said);
  const auto perm_ca = open_or_create_ca(dir, kPermissionsCaName, settings, said);

  const auto cue =
      system.security ? system.security->cue_protection : SecuritySpec::CueProtection::kNone;
  const auto governance = governance_xml(cue);
  if (read_text(governance_xml_file(dir)) == governance &&
      signed_as(governance_file(dir), governance, *perm_ca.cert)) {
    said.push_back(fmt::format("kept governance (cue protection: {})", to_string(cue)));
  } else {
    const bool had = fs::exists(governance_xml_file(dir));
    write_text(governance_xml_file(dir), governance);
    write_text(governance_file(dir), pki::sign_smime(governance, *perm_ca.cert, *perm_ca.key));
    said.push_back(fmt::format("{} governance (cue protection: {})", had ? "rewrote" : "wrote",
                               to_string(cue)));
  }

  const auto identities = identities_of(system);
  int kept = 0;
  for (const auto& identity : identities) {
    auto line = init_identity(dir, identity, id_ca, perm_ca, settings);
    if (line.empty()) {
      ++kept;
    } else {
      said.push_back(std::move(line));
    }
  }
  if (kept > 0) said.push_back(fmt::format("kept {} identities unchanged", kept));
  auto extra = identity_folders(dir);
  for (const auto& identity : identities) extra.erase(identity.name);
  for (const auto& name : extra) {
    said.push_back(fmt::format("left identity {}: not in the system file (delete {} to remove it)",
                               name, files::identity_dir(dir, name).string()));
  }
  return said;
}

std::vector<Finding> check_keystore(const SystemSpec& system, const fs::path& dir,
                                    Clock::time_point now, const KeystoreSettings& settings) {
  Checker check(dir, now, settings);
  if (!fs::is_directory(dir / "identities")) {
    check.error(fmt::format("{} is no keystore (run `oscar security init`)", dir.string()));
    return check.found_;
  }
  if (others_may_read(dir)) {
    check.error(fmt::format("{} may be read by others (chmod 700)", dir.string()));
  }
  const auto id_ca = check.ca(kIdentityCaName);
  const auto perm_ca = check.ca(kPermissionsCaName);
  if (perm_ca) {
    const auto cue =
        system.security ? system.security->cue_protection : SecuritySpec::CueProtection::kNone;
    const auto smime = read_text(governance_file(dir));
    std::string why;
    const auto text = smime ? pki::verify_smime(*smime, *perm_ca, why) : std::nullopt;
    if (!smime) {
      check.error(fmt::format("governance: no {}", governance_file(dir).string()));
    } else if (!text) {
      check.error("governance: not signed by the permissions CA: " + why);
    } else if (*text != governance_xml(cue)) {
      check.error(
          fmt::format("governance differs from what the system file gives (cue "
                      "protection: {}; run `oscar security init`)",
                      to_string(cue)));
    }
  }
  const auto identities = identities_of(system);
  for (const auto& identity : identities) check.identity(identity, id_ca.get(), perm_ca.get());
  auto extra = identity_folders(dir);
  for (const auto& identity : identities) extra.erase(identity.name);
  for (const auto& name : extra) {
    check.warning(fmt::format("{}: not in the system file (delete {} to remove it)", name,
                              files::identity_dir(dir, name).string()));
  }
  return check.found_;
}

std::vector<IdentityListing> list_keystore(const fs::path& dir) {
  if (!fs::is_directory(dir / "identities")) {
    throw std::runtime_error(
        fmt::format("{} is no keystore (run `oscar security init`)", dir.string()));
  }
  pki::Cert perm_ca;
  try {
    perm_ca = pki::read_cert(ca_cert_file(dir, kPermissionsCaName));
  } catch (const std::exception&) {
    // Each identity says it below: its permissions cannot be verified.
  }
  std::vector<IdentityListing> out;
  for (const auto& name : identity_folders(dir)) {
    IdentityListing l;
    l.name = name;
    const auto idir = files::identity_dir(dir, name);
    try {
      const auto cert = pki::read_cert(idir / files::kCertificate);
      l.subject = pki::subject(*cert);
      l.not_after = pki::not_after(*cert);
      if (!perm_ca) throw std::runtime_error("no permissions CA certificate");
      const auto smime = read_text(idir / files::kPermissions);
      if (!smime) throw std::runtime_error("no " + std::string(files::kPermissions));
      std::string why;
      const auto text = pki::verify_smime(*smime, *perm_ca, why);
      if (!text) throw std::runtime_error("permissions: " + why);
      l.publish = published_topics(*text);
    } catch (const std::exception& e) {
      l.problem = e.what();
    }
    out.push_back(std::move(l));
  }
  return out;
}

}  // namespace oscar::security
