#include "keystore.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "keystore_layout.hpp"
#include "oscar/security_files.hpp"
#include "pki.hpp"
#include "policy_xml.hpp"

namespace oscar::security {
namespace {

namespace fs = std::filesystem;
namespace files = security_files;
using namespace layout;

class Checker {
 public:
  Checker(const fs::path& dir, Clock::time_point now, const KeystoreSettings& settings)
      : dir_(dir), now_(now), settings_(settings) {}

  void error(std::string text) { found_.push_back({Finding::Level::kError, std::move(text)}); }
  void warning(std::string text) { found_.push_back({Finding::Level::kWarning, std::move(text)}); }

  // `then`: what to do before it expires.
  void dates(const std::string& what, const X509& cert, const char* then) {
    const auto until = pki::not_after(cert);
    if (until <= now_) {
      error(fmt::format("{}: certificate expired on {}", what, date(until)));
    } else if (until - now_ < settings_.renew_before) {
      warning(fmt::format("{}: certificate expires in {} days ({}); {}", what,
                          days_between(now_, until), date(until), then));
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
    dates(name, *cert, "init does not renew a CA: make a new keystore");
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
    dates(name, *cert, "`oscar security init` renews it");
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
    const auto cue = cue_protection_of(system);
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

}  // namespace oscar::security
