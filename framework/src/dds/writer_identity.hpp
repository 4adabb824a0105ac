#pragma once
// Who wrote a sample in a secured system (docs/security.md). DDS Security's PKI-DH
// authentication makes the first 47 bits of a participant's GUID prefix bits of the SHA-256 of
// its certificate's subject, and Fast DDS refuses a handshake whose GUID does not carry its
// certificate's bits: a writer's GUID prefix names the certificate it authenticated with.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fastdds/rtps/common/GuidPrefix_t.hpp>

namespace oscar::internal {

/// The 47 bits, left-aligned in six bytes (the last bit zero).
using SubjectBits = std::array<unsigned char, 6>;

/// The bits PKI-DH derives from the subject of the certificate in `pem_file`.
/// @throws std::runtime_error naming the file if it holds no certificate.
SubjectBits subject_bits_of_certificate(const std::filesystem::path& pem_file);

/// The bits a GUID prefix carries (valid only for an authenticated participant's).
SubjectBits subject_bits_of_prefix(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix);

/// The identities of a keystore a reader trusts, by their certificates' bits.
class WriterIdentities {
 public:
  /// Reads `identities`' certificates from `keystore` (identities/<name>/cert.pem); one that is
  /// missing is not recognized (its writers count as unknown).
  WriterIdentities(const std::filesystem::path& keystore,
                   const std::vector<std::string>& identities);

  /// The identity whose certificate gave `writer_prefix` its bits, or "" for none of them.
  std::string of(const eprosima::fastrtps::rtps::GuidPrefix_t& writer_prefix) const;
  /// The identities whose certificates were not found.
  const std::vector<std::string>& missing() const { return missing_; }

 private:
  std::vector<std::pair<SubjectBits, std::string>> known_;
  std::vector<std::string> missing_;
};

}  // namespace oscar::internal
