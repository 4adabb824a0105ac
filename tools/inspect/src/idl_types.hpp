#pragma once
// A small reader of OMG IDL (the self-contained `omgidl` texts OSCAR embeds and writes to MCAP)
// and a decoder that prints a serialized CDR sample of such a type as YAML-like text: how
// `oscar echo` shows any OSCAR type without compiled code for it.

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace oscar::inspect {

/// A type as the IDL declares it.
struct IdlType {
  enum class Kind { kPrimitive, kString, kSequence, kArray, kStruct, kEnum };
  Kind kind = Kind::kPrimitive;
  std::string name;                  ///< primitive keyword, or the scoped name of a struct/enum
  std::shared_ptr<IdlType> element;  ///< of a sequence or array
  std::size_t array_size = 0;
};

struct IdlMember {
  std::string name;
  IdlType type;
};

/// Every struct and enum of one or more IDL texts, by scoped name ("oscar::GvImage").
class IdlTypes {
 public:
  /// Reads one IDL text (comments and preprocessor lines are skipped).
  /// @throws std::invalid_argument naming the token it did not understand.
  void add(const std::string& idl_text);
  bool has(const std::string& scoped_name) const;

  struct Options {
    std::size_t max_items = 16;  ///< longer sequences and arrays show their first items and size
  };
  /// The sample (with its 4-byte encapsulation header) as YAML-like text, one field a line.
  /// @throws std::invalid_argument for an unknown type; std::runtime_error if the bytes end early
  ///         or have an encapsulation it does not know.
  std::string to_text(const std::string& type, std::span<const std::uint8_t> payload,
                      const Options& options) const;

 private:
  friend class Decoder;
  std::map<std::string, std::vector<IdlMember>> structs_;
  std::map<std::string, std::vector<std::string>> enums_;
};

/// A time in ns since the epoch as UTC text, e.g. "2026-11-22T09:43:47.838715176Z".
std::string utc_text(std::uint64_t ns);

}  // namespace oscar::inspect
