#include "pki.hpp"

#include <fcntl.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar::security::pki {
namespace {

struct BioFree {
  void operator()(BIO* b) const { BIO_free_all(b); }
};
using Bio = std::unique_ptr<BIO, BioFree>;

// OpenSSL's own reason for the last failure (its queue emptied), for messages.
std::string openssl_error() {
  std::string out;
  while (const auto code = ERR_get_error()) {
    char text[256];
    ERR_error_string_n(code, text, sizeof text);
    if (!out.empty()) out += "; ";
    out += text;
  }
  return out.empty() ? "unknown OpenSSL error" : out;
}

[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error(fmt::format("{}: {}", what, openssl_error()));
}

std::string bio_text(BIO* bio) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(bio, &data);
  return std::string(data, static_cast<std::size_t>(n));
}

void add_extension(X509& cert, const X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, const_cast<X509*>(issuer ? issuer : &cert), &cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (!ext || !X509_add_ext(&cert, ext, -1)) fail(fmt::format("certificate extension {}", value));
  X509_EXTENSION_free(ext);
}

Clock::time_point to_time(const ASN1_TIME* t) {
  std::tm tm{};
  if (!ASN1_TIME_to_tm(t, &tm)) fail("certificate date");
  return Clock::from_time_t(timegm(&tm));
}

// Writes `text` to a new file (replacing one there) with `mode`, then renames it into place, so
// a reader never sees half a file and a key is never readable by others, not even briefly.
void write_file(const std::filesystem::path& file, const std::string& text, mode_t mode) {
  const auto tmp = file.string() + ".new";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, mode);
  if (fd < 0) throw std::runtime_error(fmt::format("cannot write {}: {}", tmp, strerror(errno)));
  const bool ok = ::fchmod(fd, mode) == 0 &&
                  ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const int saved = errno;
  ::close(fd);
  if (!ok || std::rename(tmp.c_str(), file.c_str()) != 0) {
    throw std::runtime_error(
        fmt::format("cannot write {}: {}", file.string(), strerror(ok ? errno : saved)));
  }
}

Bio read_bio(const std::filesystem::path& file) {
  Bio bio(BIO_new_file(file.c_str(), "r"));
  if (!bio) {
    ERR_clear_error();
    throw std::runtime_error(fmt::format("cannot read {}: {}", file.string(), strerror(errno)));
  }
  return bio;
}

}  // namespace

Key new_key() {
  Key key(EVP_PKEY_Q_keygen(nullptr, nullptr, "EC", "prime256v1"));
  if (!key) fail("EC key generation");
  return key;
}

Cert issue(const EVP_PKEY& key, const std::string& common_name, const X509* issuer,
           const EVP_PKEY& issuer_key, std::chrono::hours validity, bool ca) {
  Cert cert(X509_new());
  if (!cert || !X509_set_version(cert.get(), 2)) fail("new certificate");
  // A random 63-bit serial: unique without keeping a counter in the keystore.
  unsigned char bytes[8];
  if (RAND_bytes(bytes, sizeof bytes) != 1) fail("certificate serial");
  bytes[0] &= 0x7f;
  BIGNUM* serial = BN_bin2bn(bytes, sizeof bytes, nullptr);
  if (!serial || !BN_to_ASN1_INTEGER(serial, X509_get_serialNumber(cert.get()))) fail("serial");
  BN_free(serial);
  // Valid from an hour ago: a host whose clock lags a little behind the one that ran init must
  // not refuse a certificate just issued as not valid yet.
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), -3600);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()),
                  std::chrono::duration_cast<std::chrono::seconds>(validity).count());
  X509_NAME* name = X509_get_subject_name(cert.get());
  const auto* o = reinterpret_cast<const unsigned char*>("OSCAR");
  const auto* cn = reinterpret_cast<const unsigned char*>(common_name.c_str());
  if (!X509_NAME_add_entry_by_txt(name, "O", MBSTRING_UTF8, o, -1, -1, 0) ||
      !X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, cn, -1, -1, 0)) {
    fail("certificate subject " + common_name);
  }
  if (!X509_set_issuer_name(cert.get(), issuer ? X509_get_subject_name(issuer) : name) ||
      !X509_set_pubkey(cert.get(), const_cast<EVP_PKEY*>(&key))) {
    fail("certificate of " + common_name);
  }
  add_extension(*cert, issuer, NID_basic_constraints, ca ? "critical,CA:TRUE" : "CA:FALSE");
  // A CA signs certificates and, for the permissions CA, the governance and permissions
  // documents (S/MIME signing wants digitalSignature).
  add_extension(*cert, issuer, NID_key_usage,
                ca ? "critical,digitalSignature,keyCertSign,cRLSign" : "critical,digitalSignature");
  add_extension(*cert, issuer, NID_subject_key_identifier, "hash");
  if (issuer) add_extension(*cert, issuer, NID_authority_key_identifier, "keyid:always");
  if (!X509_sign(cert.get(), const_cast<EVP_PKEY*>(&issuer_key), EVP_sha256())) {
    fail("signing the certificate of " + common_name);
  }
  return cert;
}

void write_key(const std::filesystem::path& file, const EVP_PKEY& key) {
  Bio bio(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_PrivateKey(bio.get(), const_cast<EVP_PKEY*>(&key), nullptr, nullptr, 0,
                                nullptr, nullptr)) {
    fail("encoding " + file.string());
  }
  write_file(file, bio_text(bio.get()), 0600);
}

void write_cert(const std::filesystem::path& file, const X509& cert) {
  Bio bio(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_X509(bio.get(), const_cast<X509*>(&cert))) fail("encoding " + file.string());
  write_file(file, bio_text(bio.get()), 0644);
}

Key read_key(const std::filesystem::path& file) {
  auto bio = read_bio(file);
  Key key(PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, nullptr));
  if (!key) fail(fmt::format("{} is not a PEM private key", file.string()));
  return key;
}

Cert read_cert(const std::filesystem::path& file) {
  auto bio = read_bio(file);
  Cert cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
  if (!cert) fail(fmt::format("{} is not a PEM certificate", file.string()));
  return cert;
}

std::string subject(const X509& cert) {
  Bio bio(BIO_new(BIO_s_mem()));
  // The flags Fast DDS's PKI-DH uses to print the name it then looks up in the permissions.
  X509_NAME_print_ex(bio.get(), X509_get_subject_name(&cert), 0,
                     XN_FLAG_RFC2253 & ~ASN1_STRFLGS_ESC_MSB);
  return bio_text(bio.get());
}

Clock::time_point not_before(const X509& cert) { return to_time(X509_get0_notBefore(&cert)); }
Clock::time_point not_after(const X509& cert) { return to_time(X509_get0_notAfter(&cert)); }

std::optional<std::string> not_issued_by(const X509& cert, const X509& ca) {
  std::unique_ptr<X509_STORE, decltype(&X509_STORE_free)> store(X509_STORE_new(), X509_STORE_free);
  std::unique_ptr<X509_STORE_CTX, decltype(&X509_STORE_CTX_free)> ctx(X509_STORE_CTX_new(),
                                                                      X509_STORE_CTX_free);
  if (!store || !ctx || !X509_STORE_add_cert(store.get(), const_cast<X509*>(&ca)) ||
      !X509_STORE_CTX_init(ctx.get(), store.get(), const_cast<X509*>(&cert), nullptr)) {
    fail("certificate store");
  }
  // As Fast DDS's PKI-DH verifies, less the dates.
  X509_STORE_CTX_set_flags(ctx.get(), X509_V_FLAG_CHECK_SS_SIGNATURE | X509_V_FLAG_POLICY_CHECK |
                                          X509_V_FLAG_NO_CHECK_TIME);
  if (X509_verify_cert(ctx.get()) == 1) return std::nullopt;
  ERR_clear_error();
  return X509_verify_cert_error_string(X509_STORE_CTX_get_error(ctx.get()));
}

bool key_matches(const X509& cert, const EVP_PKEY& key) {
  const bool ok = X509_check_private_key(&cert, &key) == 1;
  ERR_clear_error();
  return ok;
}

std::string sign_smime(const std::string& text, const X509& signer, const EVP_PKEY& key) {
  // What `openssl smime -sign -text` does: detached, text mode, streamed into the S/MIME output.
  const int flags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  Bio in(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  std::unique_ptr<PKCS7, decltype(&PKCS7_free)> p7(
      PKCS7_sign(const_cast<X509*>(&signer), const_cast<EVP_PKEY*>(&key), nullptr, in.get(), flags),
      PKCS7_free);
  if (!p7) fail("S/MIME signing");
  Bio out(BIO_new(BIO_s_mem()));
  if (!SMIME_write_PKCS7(out.get(), p7.get(), in.get(), flags)) fail("S/MIME writing");
  return bio_text(out.get());
}

std::optional<std::string> verify_smime(const std::string& smime, const X509& ca,
                                        std::string& error) {
  Bio in(BIO_new_mem_buf(smime.data(), static_cast<int>(smime.size())));
  BIO* content = nullptr;
  std::unique_ptr<PKCS7, decltype(&PKCS7_free)> p7(SMIME_read_PKCS7(in.get(), &content),
                                                   PKCS7_free);
  Bio signed_content(content);
  if (!p7) {
    error = "not an S/MIME document: " + openssl_error();
    return std::nullopt;
  }
  std::unique_ptr<X509_STORE, decltype(&X509_STORE_free)> store(X509_STORE_new(), X509_STORE_free);
  if (!store || !X509_STORE_add_cert(store.get(), const_cast<X509*>(&ca))) fail("store");
  Bio out(BIO_new(BIO_s_mem()));
  // As Fast DDS's Access-Permissions plugin verifies.
  if (PKCS7_verify(p7.get(), nullptr, store.get(), signed_content.get(), out.get(), PKCS7_TEXT) !=
      1) {
    error = "signature does not verify against the CA: " + openssl_error();
    return std::nullopt;
  }
  std::string text = bio_text(out.get());
  std::erase(text, '\r');  // text mode signs CRLF line ends
  return text;
}

}  // namespace oscar::security::pki
