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

}  // namespace

std::vector<std::string> init_keystore(const SystemSpec& system, const fs::path& dir,
                                       const KeystoreSettings& settings) {
  std::vector<std::string> said;
  const bool existed = fs::exists(dir);
  // init makes the folder owner-only and writes into it: never do that to a folder of something
  // else (a mistyped --keystore $HOME).
  if (existed && !fs::is_directory(dir / "identities") && !fs::is_empty(dir)) {
    throw std::runtime_error(fmt::format(
        "{} exists and is no keystore (it has no identities/ folder): give a new or empty folder",
        dir.string()));
  }
  if (existed && others_may_read(dir)) {
    said.push_back("made " + dir.string() + " owner-only (0700)");
  }
  make_private_dir(dir);
  make_private_dir(dir / "private");
  fs::create_directories(dir / "public");
  make_private_dir(dir / "identities");
  const auto id_ca = open_or_create_ca(dir, kIdentityCaName, settings, said);
  const auto perm_ca = open_or_create_ca(dir, kPermissionsCaName, settings, said);

  const auto cue = cue_protection_of(system);
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

}  // namespace oscar::security
