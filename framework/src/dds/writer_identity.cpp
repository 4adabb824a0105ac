#include "dds/writer_identity.hpp"

#include <cstdio>
#include <memory>
#include <stdexcept>

#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>

#include "oscar/security_files.hpp"

namespace oscar::internal {

SubjectBits subject_bits_of_certificate(const std::filesystem::path& pem_file) {
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(pem_file.c_str(), "r"),
                                                             &std::fclose);
  const std::unique_ptr<X509, void (*)(X509*)> cert(
      file ? PEM_read_X509(file.get(), nullptr, nullptr, nullptr) : nullptr, &X509_free);
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (!cert || !X509_NAME_digest(X509_get_subject_name(cert.get()), EVP_sha256(), md, &length)) {
    throw std::runtime_error(pem_file.string() + ": no certificate (run oscar security init)");
  }
  SubjectBits bits{md[0], md[1], md[2], md[3], md[4], md[5]};
  bits[5] &= 0xFE;
  return bits;
}

SubjectBits subject_bits_of_prefix(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  // The prefix holds the bits from its second bit on (its first bit says "derived").
  SubjectBits bits{};
  for (std::size_t i = 0; i < bits.size(); ++i) {
    bits[i] = static_cast<unsigned char>((prefix.value[i] << 1) | (prefix.value[i + 1] >> 7));
  }
  bits[5] &= 0xFE;
  return bits;
}

WriterIdentities::WriterIdentities(const std::filesystem::path& keystore,
                                   const std::vector<std::string>& identities) {
  for (const auto& identity : identities) {
    const auto pem =
        security_files::identity_dir(keystore, identity) / security_files::kCertificate;
    try {
      known_.emplace_back(subject_bits_of_certificate(pem), identity);
    } catch (const std::runtime_error&) {
      missing_.push_back(identity);  // its writers stay unknown: their commands are refused
    }
  }
}

std::string WriterIdentities::of(
    const eprosima::fastrtps::rtps::GuidPrefix_t& writer_prefix) const {
  if ((writer_prefix.value[0] & 0x80) == 0) return "";  // not derived from a certificate
  const auto bits = subject_bits_of_prefix(writer_prefix);
  for (const auto& [known, identity] : known_) {
    if (known == bits) return identity;
  }
  return "";
}

}  // namespace oscar::internal
