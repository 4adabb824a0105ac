#include "keystore.hpp"

#include <initializer_list>
#include <stdexcept>

#include <fmt/format.h>

#include "keystore_layout.hpp"
#include "oscar/security_files.hpp"
#include "pki.hpp"

namespace oscar::security {
namespace {

namespace fs = std::filesystem;
namespace files = security_files;
using namespace layout;

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

}  // namespace

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
