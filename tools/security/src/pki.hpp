#pragma once
// The public-key work of the keystore, through the OpenSSL library: EC keys on prime256v1,
// X.509 certificates signed with ECDSA-SHA256, and S/MIME signatures (PKCS#7, detached, text)
// as the DDS Security builtin plugins read them.

#include <openssl/evp.h>
#include <openssl/x509.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace oscar::security::pki {

struct KeyFree {
  void operator()(EVP_PKEY* key) const { EVP_PKEY_free(key); }
};
struct CertFree {
  void operator()(X509* cert) const { X509_free(cert); }
};
using Key = std::unique_ptr<EVP_PKEY, KeyFree>;
using Cert = std::unique_ptr<X509, CertFree>;
using Clock = std::chrono::system_clock;

/// A new EC key pair on prime256v1.
Key new_key();

/// A certificate for `key` with subject "CN=<common_name>,O=OSCAR", valid from an hour ago
/// until `validity` from now, signed by `issuer`/`issuer_key`, or self-signed when `issuer` is
/// null. A CA certificate may sign certificates and documents; any other only signs
/// (authentication).
Cert issue(const EVP_PKEY& key, const std::string& common_name, const X509* issuer,
           const EVP_PKEY& issuer_key, std::chrono::hours validity, bool ca);

/// Writes a private key as unencrypted PKCS#8 PEM, readable by its owner only (0600).
/// @throws std::runtime_error naming the file.
void write_key(const std::filesystem::path& file, const EVP_PKEY& key);
void write_cert(const std::filesystem::path& file, const X509& cert);
/// @throws std::runtime_error naming the file if it is missing or not a PEM key/certificate.
Key read_key(const std::filesystem::path& file);
Cert read_cert(const std::filesystem::path& file);

/// The subject as RFC 2253 text, most specific first ("CN=registry,O=OSCAR"), as Fast DDS
/// compares it with a permissions grant.
std::string subject(const X509& cert);
Clock::time_point not_before(const X509& cert);
Clock::time_point not_after(const X509& cert);

/// Why `cert` is not signed by `ca` (a self-signed certificate passes `ca` = itself), or nothing
/// when it is. Validity dates are not checked here (expiry is its own finding).
std::optional<std::string> not_issued_by(const X509& cert, const X509& ca);
/// True if `key` is the private key of `cert`'s public key.
bool key_matches(const X509& cert, const EVP_PKEY& key);

/// `text` signed by `signer` as S/MIME (multipart/signed, detached PKCS#7, text mode).
std::string sign_smime(const std::string& text, const X509& signer, const EVP_PKEY& key);
/// The signed text of an S/MIME document if `ca` issued its signer and the signature holds
/// (line ends as LF); otherwise the error, in `error`.
std::optional<std::string> verify_smime(const std::string& smime, const X509& ca,
                                        std::string& error);

}  // namespace oscar::security::pki
